// sextant::compiled: every back-end for spatial MRPT rawlogs (SE(3) odometry, 3D range and bearing) (docs/build_times.md).
#include "define_instances.hpp"
#include "sextant/models/range_bearing_3d.hpp"
#include "sextant/models/se3_odometry.hpp"

SEXTANT_DEFINE_INSTANCES(sextant::Se3Odometry, sextant::RangeBearing3D)
