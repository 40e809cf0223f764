// sextant::compiled: every back-end for the thesis's beacon ship (docs/build_times.md).
#include "define_instances.hpp"
#include "sextant/models/beacon_ship_2d.hpp"

SEXTANT_DEFINE_INSTANCES(sextant::BeaconShip2D, sextant::BeaconOffset2D)
