// sextant::compiled: every back-end for the MRCLAM robots, additive and in the world chart (unicycle, range and bearing) (docs/build_times.md).
#include "define_instances.hpp"
#include "sextant/models/range_bearing_2d.hpp"
#include "sextant/models/se2_world_frame.hpp"
#include "sextant/models/unicycle.hpp"

SEXTANT_DEFINE_INSTANCES(sextant::Unicycle, sextant::RangeBearing2D)
SEXTANT_DEFINE_INSTANCES(sextant::InWorldFrame<sextant::Unicycle>, sextant::SeenInWorldFrame<sextant::RangeBearing2D>)
