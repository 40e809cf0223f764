// sextant::compiled: every back-end for the thesis's 12D camera around the globe (docs/build_times.md).
#include "define_instances.hpp"
#include "sextant/models/euler_camera_12d.hpp"

SEXTANT_DEFINE_INSTANCES(sextant::EulerCamera12D, sextant::PointInCamera3D)
