// Writing your own models: a unicycle robot with odometry (v, omega) that measures landmarks by
// range and bearing. Check the Jacobians, then plug the models into EKF-SLAM unchanged.
#include <cmath>
#include <cstdio>
#include <sextant/sextant.hpp>

/// State (x, y, heading); control (v, omega); x' = x + dt (v cos h, v sin h, omega).
struct Unicycle {
  using State = Eigen::Vector3d;
  using Control = Eigen::Vector2d;
  struct Space : sextant::EuclideanSpace<3> {  // heading wraps
    static State plus(const State& x, const Eigen::Vector3d& d) {
      State out = x + d;
      out(2) = sextant::wrap_angle(out(2));
      return out;
    }
    static Eigen::Vector3d minus(const State& a, const State& b) {
      Eigen::Vector3d d = a - b;
      d(2) = sextant::wrap_angle(d(2));
      return d;
    }
  };
  static constexpr int kDim = 3;
  double sigma_v = 0.05, sigma_omega = 0.02;

  sextant::MotionPrediction<State, 3> predict(const State& x, const Control& u, double dt) const {
    const double c = std::cos(x(2)), s = std::sin(x(2));
    sextant::MotionPrediction<State, 3> out;
    out.x = Space::plus(x, Eigen::Vector3d(dt * u(0) * c, dt * u(0) * s, dt * u(1)));
    out.J_x_x << 1, 0, -dt * u(0) * s, 0, 1, dt * u(0) * c, 0, 0, 1;
    Eigen::Matrix<double, 3, 2> V;  // dx'/du
    V << dt * c, 0, dt * s, 0, 0, dt;
    out.R = V * Eigen::Vector2d(sigma_v * sigma_v, sigma_omega * sigma_omega).asDiagonal() * V.transpose();
    return out;
  }
};

/// z = (range, bearing) of a 2D landmark from the robot.
struct RangeBearing {
  using Landmark = Eigen::Vector2d;
  using Measurement = Eigen::Vector2d;
  double sigma_range = 0.1, sigma_bearing = 0.01;

  sextant::MeasurementPrediction<2, 3, 2> predict(const Eigen::Vector3d& x, const Landmark& m) const {
    const Eigen::Vector2d d = m - x.head<2>();
    const double q = d.squaredNorm(), r = std::sqrt(q);
    sextant::MeasurementPrediction<2, 3, 2> out;
    out.z << r, sextant::wrap_angle(std::atan2(d.y(), d.x()) - x(2));
    out.J_z_m << d.x() / r, d.y() / r, -d.y() / q, d.x() / q;
    out.J_z_x << -out.J_z_m, Eigen::Vector2d(0.0, -1.0);
    out.Q = Eigen::Vector2d(sigma_range * sigma_range, sigma_bearing * sigma_bearing).asDiagonal();
    return out;
  }
  Measurement residual(const Measurement& z, const Measurement& z_hat) const {
    return {z(0) - z_hat(0), sextant::wrap_angle(z(1) - z_hat(1))};
  }
  sextant::LandmarkInit<2, 3, 2> initialize(const Eigen::Vector3d& x, const Measurement& z) const {
    const double a = x(2) + z(1), c = std::cos(a), s = std::sin(a);
    sextant::LandmarkInit<2, 3, 2> out;
    out.m = x.head<2>() + z(0) * Eigen::Vector2d(c, s);
    out.J_m_x << 1, 0, -z(0) * s, 0, 1, z(0) * c;
    out.J_m_z << c, -z(0) * s, s, z(0) * c;
    out.Q = Eigen::Vector2d(sigma_range * sigma_range, sigma_bearing * sigma_bearing).asDiagonal();
    return out;
  }
};

int main() {
  // 1. Check every Jacobian against central differences.
  const auto motion_check = sextant::testing::check_motion_jacobians(Unicycle{}, {1, 2, 0.3}, {1.0, 0.1}, 0.1);
  const auto sensor_check = sextant::testing::check_measurement_jacobians<Unicycle>(RangeBearing{}, {1, 2, 0.3}, {4, -1});
  if (!motion_check || !sensor_check) {
    std::printf("Jacobian check failed:\n%s%s", motion_check.report.c_str(), sensor_check.report.c_str());
    return 1;
  }
  // 2. Use them: drive a circle around four landmarks.
  sextant::EkfSlam<Unicycle, RangeBearing> ekf{Unicycle{}, RangeBearing{},
                                               {Eigen::Vector3d::Zero(), 1e-6 * Eigen::Matrix3d::Identity()}};
  const std::vector<Eigen::Vector2d> landmarks{{5, 5}, {-5, 5}, {-5, 15}, {5, 15}};
  Eigen::Vector3d truth = Eigen::Vector3d::Zero();
  for (int k = 0; k < 600; ++k) {
    const Eigen::Vector2d u(1.0, 0.1);
    truth = Unicycle{}.predict(truth, u, 0.1).x;
    ekf.predict(u, 0.1);
    std::vector<sextant::Observation<Eigen::Vector2d>> observations;
    for (std::size_t j = 0; j < landmarks.size(); ++j)
      observations.push_back({j, RangeBearing{}.predict(truth, landmarks[j]).z});
    ekf.update(observations);
  }
  std::printf("after 600 steps: pose (%.3f, %.3f, %.3f), truth (%.3f, %.3f, %.3f), %zu landmarks\n", ekf.pose().mean(0),
              ekf.pose().mean(1), ekf.pose().mean(2), truth(0), truth(1), truth(2), ekf.num_landmarks());
  return 0;
}
