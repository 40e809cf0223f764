// Uses the installed headers end to end: simulate a short ship run, filter it, check the error.
#include <cstdio>
#include <sextant/sextant.hpp>

int main() {
  sextant::sim::Ship2DOptions options;
  options.num_steps = 100;
  const auto data = sextant::sim::simulate_ship_2d(options);
  sextant::EkfSlam<sextant::BeaconShip2D, sextant::BeaconOffset2D> ekf{data.motion, data.sensor, data.prior};
  const auto record = sextant::eval::run(ekf, data.steps);
  const double error = sextant::eval::absolute_error(record.steps.back().pose.mean, data.true_poses.back());
  std::printf("consumer: %zu steps, %zu landmarks, final pose error %.3f km\n", record.steps.size(),
              ekf.num_landmarks(), error);
  return (ekf.num_landmarks() > 0 && error < 20.0) ? 0 : 1;
}
