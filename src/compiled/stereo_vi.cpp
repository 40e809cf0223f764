// sextant::compiled: every back-end for seed 004's visual-inertial SLAM (IMU velocities, stereo pixels on SE(3)) (docs/build_times.md).
#include "define_instances.hpp"
#include "sextant/models/stereo_imu_se3.hpp"

SEXTANT_DEFINE_INSTANCES(sextant::ImuVelocitySe3, sextant::StereoPixelsSe3)
