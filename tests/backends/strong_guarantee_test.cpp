// The strong guarantee, tested by fault injection: every call a back-end makes into its models
// (motion predict, measurement predict/residual/initialize, and the state space's plus/minus) can
// be made to fail. For each operation (predict, update, remove_landmark, optimize) and each n, the
// n-th model call throws (or returns NaN); the operation must then throw and leave the back-end
// bit-for-bit as it was, and a twin that never saw a failure must end in exactly the same state.
#include <gtest/gtest.h>

#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "sextant/backends/ekf_slam.hpp"
#include "sextant/backends/fast_slam.hpp"
#include "sextant/backends/graph_slam.hpp"
#include "sextant/backends/seif_slam.hpp"
#include "sextant/models/beacon_ship_2d.hpp"
#include "support/batch_least_squares.hpp"

namespace sextant {
namespace {

/// The fault: armed with a call count, it fires once at that call.
struct Fault {
  static inline long countdown = -1;  ///< calls left before the fault; -1 = disarmed
  static inline bool poison = false;  ///< return NaN instead of throwing
  static inline bool fired = false;
  static void arm(long calls, bool nan) { countdown = calls, poison = nan, fired = false; }
  static void disarm() { countdown = -1; }
  /// True when this call is the faulty one and must return NaN; throws when it must throw.
  static bool hit() {
    if (countdown < 0 || countdown-- != 0) return false;
    fired = true;
    if (!poison) throw numerical_error("injected fault");
    return true;
  }
};
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

struct FaultySpace {
  using Point = Eigen::Vector2d;
  static Point plus(const Point& x, const Point& d) { return Fault::hit() ? Point::Constant(kNaN) : Point(x + d); }
  static Point minus(const Point& a, const Point& b) { return Fault::hit() ? Point::Constant(kNaN) : Point(a - b); }
  static bool is_finite(const Point& x) { return x.allFinite(); }
};

struct FaultyMotion : BeaconShip2D {
  using Space = FaultySpace;
  FaultyMotion() : BeaconShip2D(test::kLinearMotion) {}
  MotionPrediction<State, 2> predict(const State& x, const Control& u, double dt) const {
    auto out = BeaconShip2D::predict(x, u, dt);
    if (Fault::hit()) out.R(0, 0) = kNaN;
    return out;
  }
};

struct FaultySensor : BeaconOffset2D {
  FaultySensor() : BeaconOffset2D(test::kLinearSensor) {}
  MeasurementPrediction<2, 2, 2> predict(const Eigen::Vector2d& x, const Landmark& m) const {
    auto out = BeaconOffset2D::predict(x, m);
    if (Fault::hit()) out.J_z_x(0, 0) = kNaN;
    return out;
  }
  Measurement residual(const Measurement& z, const Measurement& z_hat) const {
    return Fault::hit() ? Measurement::Constant(kNaN) : BeaconOffset2D::residual(z, z_hat);
  }
  LandmarkInit<2, 2, 2> initialize(const Eigen::Vector2d& x, const Measurement& z) const {
    auto out = BeaconOffset2D::initialize(x, z);
    if (Fault::hit()) out.m(1) = kNaN;
    return out;
  }
};

/// Everything observable of a back-end, flattened to doubles for a bitwise comparison.
template <class Backend>
std::vector<double> fingerprint(const Backend& backend) {
  std::vector<double> out;
  auto put = [&](const auto& matrix) {
    for (Eigen::Index i = 0; i < matrix.size(); ++i) out.push_back(matrix.data()[i]);
  };
  const auto pose = backend.pose();
  put(pose.mean);
  put(pose.cov);
  for (const auto& landmark : backend.map()) {
    out.push_back(static_cast<double>(landmark.id));
    put(landmark.mean);
    put(landmark.cov);
  }
  if constexpr (requires { backend.covariance(); }) put(backend.covariance());
  if constexpr (requires { backend.information_matrix(); }) put(Eigen::MatrixXd(backend.information_matrix()));
  if constexpr (requires { backend.information().residual(); }) put(backend.information().residual());
  if constexpr (requires { backend.active_landmarks(); })
    for (LandmarkId id : backend.active_landmarks()) out.push_back(static_cast<double>(id));
  if constexpr (requires { backend.pose_means(); })
    for (const auto& x : backend.pose_means()) put(x);
  if constexpr (requires { backend.particles(); }) {
    for (const auto& particle : backend.particles()) {
      put(particle.x);
      put(particle.cov);
      out.push_back(particle.log_weight);
      for (std::size_t j = 0; j < particle.landmarks.size(); ++j) {
        put(particle.landmarks[j].mean);
        put(particle.landmarks[j].cov);
        out.push_back(particle.landmarks[j].alive);
      }
    }
    out.push_back(static_cast<double>(backend.resamplings()));
  }
  return out;
}

/// Bitwise equality (so that -0.0 != 0.0 and every last bit counts).
bool bitwise_equal(const std::vector<double>& a, const std::vector<double>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0;
}

struct EkfBatch {
  static auto make() {
    return EkfSlam<FaultyMotion, FaultySensor>{FaultyMotion{}, FaultySensor{}, test::kLinearPrior, {.batch_update = true}};
  }
};
struct EkfSequential {
  static auto make() {
    return EkfSlam<FaultyMotion, FaultySensor>{FaultyMotion{}, FaultySensor{}, test::kLinearPrior, {.batch_update = false}};
  }
};
struct EkfJoseph {
  static auto make() {
    return EkfSlam<FaultyMotion, FaultySensor>{FaultyMotion{}, FaultySensor{}, test::kLinearPrior,
                                               {.covariance_update = CovarianceUpdate::joseph, .gate_probability = 0.999}};
  }
};
struct EkfIterated {
  static auto make() {
    return EkfSlam<FaultyMotion, FaultySensor>{FaultyMotion{}, FaultySensor{}, test::kLinearPrior, {.iterations = 3}};
  }
};
struct SeifSparsified {
  static auto make() {
    return SeifSlam<FaultyMotion, FaultySensor>{FaultyMotion{}, FaultySensor{}, test::kLinearPrior, {.max_active = 3}};
  }
};
struct SeifRelocalization {
  static auto make() {
    return SeifSlam<FaultyMotion, FaultySensor>{
        FaultyMotion{}, FaultySensor{}, test::kLinearPrior,
        {.max_active = 2, .sparsification = SeifSparsification::relocalization, .estimate = SeifEstimate::exact_mean}};
  }
};
struct SeifRelocalizationIterated {  // the iterated SEIF: every step iterated, relocalizing or not
  static auto make() {
    return SeifSlam<FaultyMotion, FaultySensor>{FaultyMotion{}, FaultySensor{}, test::kLinearPrior,
                                                {.max_active = 2,
                                                 .sparsification = SeifSparsification::relocalization,
                                                 .estimate = SeifEstimate::exact_mean,
                                                 .iterations = 3}};
  }
};
struct SeifCoordinateDescent {
  static auto make() {
    return SeifSlam<FaultyMotion, FaultySensor>{
        FaultyMotion{}, FaultySensor{}, test::kLinearPrior,
        {.max_active = 4, .mean_recovery = MeanRecovery::coordinate_descent, .exact_recovery_period = 3}};
  }
};
struct Graph {
  static auto make() { return GraphSlam<FaultyMotion, FaultySensor>{FaultyMotion{}, FaultySensor{}, test::kLinearPrior}; }
};
struct GraphOnline {
  static auto make() {
    return GraphSlam<FaultyMotion, FaultySensor>{FaultyMotion{}, FaultySensor{}, test::kLinearPrior, {.incremental = true}};
  }
};
struct GraphFixedLag {
  static auto make() {
    return GraphSlam<FaultyMotion, FaultySensor>{FaultyMotion{}, FaultySensor{}, test::kLinearPrior, {.lag = 3}};
  }
};
struct FastSlamOne {
  static auto make() {
    return FastSlam<FaultyMotion, FaultySensor>{FaultyMotion{}, FaultySensor{}, test::kLinearPrior,
                                                {.particles = 6, .version = FastSlamVersion::v1, .resample_threshold = 0.9}};
  }
};
struct FastSlamTwo {
  static auto make() {
    return FastSlam<FaultyMotion, FaultySensor>{FaultyMotion{}, FaultySensor{}, test::kLinearPrior,
                                                {.particles = 6, .version = FastSlamVersion::v2, .resample_threshold = 0.9}};
  }
};
struct FastSlamTwoIterated {  // a fault in any pass of the iterated proposal
  static auto make() {
    return FastSlam<FaultyMotion, FaultySensor>{
        FaultyMotion{}, FaultySensor{}, test::kLinearPrior,
        {.particles = 6, .version = FastSlamVersion::v2, .resample_threshold = 0.9, .iterations = 3}};
  }
};

template <class Config>
class StrongGuarantee : public ::testing::Test {
 protected:
  using Backend = decltype(Config::make());

  /// Runs `op` on `faulty` with the n-th model call failing, for n = 0, 1, ... until it runs
  /// through without reaching the fault; every failed attempt must leave `faulty` unchanged.
  /// Then runs `op` on `clean` and expects both to be identical.
  template <class Op>
  void sweep(Backend& faulty, Backend& clean, Op op, const std::string& what) {
    for (long n = 0;; ++n) {
      const auto before = fingerprint(faulty);
      Fault::arm(n, false);
      try {
        op(faulty);
      } catch (const numerical_error& e) {
        Fault::disarm();
        ASSERT_TRUE(Fault::fired) << what << ": threw without the fault: " << e.what();
        ASSERT_TRUE(bitwise_equal(before, fingerprint(faulty))) << what << ": state changed by a failure at call " << n;
        continue;
      }
      Fault::disarm();
      ASSERT_FALSE(Fault::fired) << what << ": the fault at call " << n << " was swallowed";
      faults_ += n;
      break;
    }
    op(clean);
    ASSERT_TRUE(bitwise_equal(fingerprint(faulty), fingerprint(clean))) << what << ": failed attempts left a trace";
  }

  /// The same with NaN from the n-th call: the operation throws (state unchanged) or succeeds
  /// with a finite state. Runs on copies, so `backend` itself is not changed.
  template <class Op>
  void poison_sweep(const Backend& backend, Op op, const std::string& what) {
    for (long n = 0;; ++n) {
      Backend copy = backend;
      const auto before = fingerprint(copy);
      Fault::arm(n, true);
      try {
        op(copy);
      } catch (const error& e) {
        Fault::disarm();
        ASSERT_TRUE(bitwise_equal(before, fingerprint(copy))) << what << ": NaN at call " << n << " changed the state";
        continue;
      }
      Fault::disarm();
      if (!Fault::fired) break;
      for (double v : fingerprint(copy)) ASSERT_TRUE(std::isfinite(v)) << what << ": NaN at call " << n << " got through";
    }
  }

  long faults_ = 0;
};

using Configs = ::testing::Types<EkfBatch, EkfSequential, EkfJoseph, EkfIterated, SeifSparsified, SeifRelocalization,
                                 SeifRelocalizationIterated, SeifCoordinateDescent, Graph,
                                 GraphOnline, GraphFixedLag, FastSlamOne, FastSlamTwo, FastSlamTwoIterated>;
TYPED_TEST_SUITE(StrongGuarantee, Configs);

/// 10 steps on the linear test problem, a removal every third step (the removed id comes back
/// later: the same id re-observed after removal), and for GraphSLAM an optimization every fourth.
TYPED_TEST(StrongGuarantee, EveryModelCallThatFailsLeavesTheBackendUnchanged) {
  using Backend = typename TestFixture::Backend;
  Backend faulty = TypeParam::make(), clean = TypeParam::make();
  const auto steps = test::random_linear_steps(10, 6, 41);
  for (std::size_t k = 0; k < steps.size(); ++k) {
    const auto& step = steps[k];
    const std::string at = "step " + std::to_string(k);
    auto predict = [&](Backend& b) { b.predict(step.control, step.dt); };
    auto update = [&](Backend& b) { b.update(step.observations); };
    this->poison_sweep(faulty, predict, at + " predict");
    this->sweep(faulty, clean, predict, at + " predict");
    this->poison_sweep(faulty, update, at + " update");
    this->sweep(faulty, clean, update, at + " update");
    if (k % 3 == 2) {
      const LandmarkId id = faulty.landmark_ids().front();
      this->sweep(faulty, clean, [&](Backend& b) { b.remove_landmark(id); }, at + " remove_landmark");
    }
    if constexpr (requires { faulty.optimize(); })
      if (k % 4 == 3) this->sweep(faulty, clean, [&](Backend& b) { b.optimize(); }, at + " optimize");
    if (this->HasFatalFailure()) return;
  }
  // Every predict and update calls a model at least once, so each must have seen a fault.
  EXPECT_GE(this->faults_, static_cast<long>(2 * steps.size())) << "the sweep must have injected faults";
}

}  // namespace
}  // namespace sextant
