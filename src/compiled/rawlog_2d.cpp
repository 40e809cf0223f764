// sextant::compiled: every back-end for planar MRPT rawlogs (SE(2) odometry, range and bearing) (docs/build_times.md).
#include "define_instances.hpp"
#include "sextant/models/range_bearing_2d.hpp"
#include "sextant/models/se2_odometry.hpp"

SEXTANT_DEFINE_INSTANCES(sextant::Se2Odometry, sextant::RangeBearing2D)
