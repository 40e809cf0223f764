// sextant::compiled: every back-end for planar iSAM text data sets (SE(2) odometry, points in the robot frame), in the
// additive chart and in the world chart the runner's filters use (docs/build_times.md).
#include "define_instances.hpp"
#include "sextant/models/point_in_robot_frame_2d.hpp"
#include "sextant/models/se2_odometry.hpp"
#include "sextant/models/se2_world_frame.hpp"

SEXTANT_DEFINE_INSTANCES(sextant::Se2Odometry, sextant::PointInRobotFrame2D)
SEXTANT_DEFINE_INSTANCES(sextant::InWorldFrame<sextant::Se2Odometry>, sextant::SeenInWorldFrame<sextant::PointInRobotFrame2D>)
