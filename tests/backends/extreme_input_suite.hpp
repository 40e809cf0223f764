#pragma once
// Extreme inputs to every back-end, for every model pair (issue 15): magnitudes near the double
// range, near-zero and huge noise, thousands of new landmarks in one update, removal of a landmark
// just added and its id observed again. Each operation either works and leaves finite estimates,
// or throws a sextant::error that names the problem and leaves the estimator as it was. Never NaN
// or Inf in pose() / map(), never an accepted input after which pose() / map() throw, never
// another exception, never a crash.
//
// A type-parameterized suite: extreme_input_<world>_test.cpp instantiates it for one model pair and
// every back-end (one file per model pair so that a build compiles them side by side).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <optional>
#include <string>
#include <vector>

#include "sextant/backends/ekf_slam.hpp"
#include "sextant/backends/fast_slam.hpp"
#include "sextant/backends/graph_slam.hpp"
#include "sextant/backends/seif_slam.hpp"
#include "sextant/core/error.hpp"

namespace sextant::test {

/// One model pair as the suite needs it: `motion(sigma)` and `sensor(sigma)` with the world's usual
/// noise standard deviations (0.01-1) multiplied by sigma, `control(scale, sigma)` a usual control
/// with its magnitude times scale, `measurement(j, scale)` a plausible measurement of landmark j
/// (distinct landmarks for distinct j) at scale times the usual distance, `prior()`.
template <class World>
concept ExtremeInputWorld = requires(int j, double s) {
  World::motion(s);
  World::sensor(s);
  World::control(s, s);
  World::measurement(j, s);
  World::prior();
  World::kName;
};

/// The back-ends: make(motion, sensor, prior).
/// EKF in its three update modes (the outside probe found them disagreeing on extreme input).
enum class EkfMode { batch, sequential, joseph };
template <EkfMode Mode>
struct ExtremeEkf {
  static constexpr const char* kName = Mode == EkfMode::batch ? "EKF" : Mode == EkfMode::sequential ? "EKF sequential" : "EKF Joseph";
  template <class Motion, class Sensor, class Prior>
  static auto make(Motion motion, Sensor sensor, const Prior& prior) {
    EkfOptions options;
    options.batch_update = Mode != EkfMode::sequential;
    if (Mode == EkfMode::joseph) options.covariance_update = CovarianceUpdate::joseph;
    return EkfSlam<Motion, Sensor>{motion, sensor, prior, options};
  }
};
struct ExtremeSeif {
  static constexpr const char* kName = "SEIF";
  template <class Motion, class Sensor, class Prior>
  static auto make(Motion motion, Sensor sensor, const Prior& prior) {
    return SeifSlam<Motion, Sensor>{motion, sensor, prior, {.max_active = 4}};
  }
};
struct ExtremeGraph {
  static constexpr const char* kName = "GraphSLAM";
  template <class Motion, class Sensor, class Prior>
  static auto make(Motion motion, Sensor sensor, const Prior& prior) {
    return GraphSlam<Motion, Sensor>{motion, sensor, prior};
  }
};
/// FastSLAM 1.0 and 2.0 share one instantiation; the version is a run-time option.
template <FastSlamVersion V>
struct ExtremeFastSlam {
  static constexpr const char* kName = V == FastSlamVersion::v1 ? "FastSLAM 1.0" : "FastSLAM 2.0";
  template <class Motion, class Sensor, class Prior>
  static auto make(Motion motion, Sensor sensor, const Prior& prior) {
    return FastSlam<Motion, Sensor>{motion, sensor, prior, {.particles = 10, .version = V}};
  }
};

template <class W, class B>
struct ExtremeCase {
  using World = W;
  using Backend = B;
};

/// What a caller can see of an estimator: its estimates, or the sextant::error they throw.
template <class Estimator>
struct Observable {
  explicit Observable(const Estimator& e) : ids(e.landmark_ids()) {
    try {
      pose = e.pose();
      map = e.map();
    } catch (const error& err) {
      estimate_error = err.what();
    }
  }
  /// Bit for bit (NaN equals the same NaN).
  bool operator==(const Observable& o) const {
    if (ids != o.ids || estimate_error != o.estimate_error || pose.has_value() != o.pose.has_value()) return false;
    if (pose && !(same_bits(pose->mean, o.pose->mean) && same_bits(pose->cov, o.pose->cov))) return false;
    if (map.size() != o.map.size()) return false;
    for (std::size_t i = 0; i < map.size(); ++i)
      if (map[i].id != o.map[i].id || !same_bits(map[i].mean, o.map[i].mean) || !same_bits(map[i].cov, o.map[i].cov))
        return false;
    return true;
  }
  template <class A>
  static bool same_bits(const A& a, const A& b) {
    if constexpr (requires { a.data(); a.size(); })
      return a.size() == b.size() && std::memcmp(a.data(), b.data(), sizeof(*a.data()) * static_cast<std::size_t>(a.size())) == 0;
    else
      return a == b;  // a pose type without contiguous storage
  }
  /// Empty when every estimate is finite; else what is not.
  std::string non_finite() const {
    if (pose && !(pose->mean.allFinite() && pose->cov.allFinite())) return "pose() is not finite";
    for (const auto& m : map)
      if (!(m.mean.allFinite() && m.cov.allFinite())) return "map() entry of landmark " + std::to_string(m.id) + " is not finite";
    return {};
  }
  std::vector<LandmarkId> ids;
  std::optional<typename Estimator::PoseEstimate> pose;
  typename Estimator::MapEstimate map;
  std::string estimate_error;  ///< what pose() or map() threw, if they did
};

/// 1e+300 rather than std::to_string's 301 digits.
inline std::string sci(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", v);
  return text;
}

template <class Case>
class ExtremeInput : public ::testing::Test {
 protected:
  using World = typename Case::World;
  using Motion = decltype(World::motion(1.0));
  using Sensor = decltype(World::sensor(1.0));
  using Estimator = decltype(Case::Backend::make(World::motion(1.0), World::sensor(1.0), World::prior()));
  using Obs = Observation<typename Sensor::Measurement>;
  static_assert(ExtremeInputWorld<World>);
  static constexpr bool kHasControl = [] {
    using Control = decltype(World::control(1.0, 1.0));
    if constexpr (requires { Control::RowsAtCompileTime; }) return Control::RowsAtCompileTime != 0;
    else return true;  // a struct such as an odometry increment
  }();

  static Estimator make(double sigma = 1.0) {
    return Case::Backend::make(World::motion(sigma), World::sensor(sigma), World::prior());
  }
  static std::vector<Obs> observations(LandmarkId first, int count, double scale = 1.0) {
    std::vector<Obs> out;
    for (int j = 0; j < count; ++j) out.push_back({first + static_cast<LandmarkId>(j), World::measurement(j, scale)});
    return out;
  }
  /// A few ordinary steps so that the estimator has a map and correlations.
  static void warm_up(Estimator& e, double sigma = 1.0) {
    for (int k = 0; k < 3; ++k) {
      e.predict(World::control(1.0, sigma), 0.1);
      e.update(observations(1, 4));
    }
  }

  /// Runs `op`: it must either succeed and leave finite estimates, or throw a sextant::error with a
  /// message and leave what a caller can observe unchanged. Returns whether it succeeded.
  template <class Op>
  bool finite_or_clean_error(Estimator& e, Op op, const std::string& what) {
    const Observable<Estimator> before(e);
    try {
      op();
    } catch (const error& err) {
      EXPECT_FALSE(std::string(err.what()).empty()) << what;
      EXPECT_TRUE(Observable<Estimator>(e) == before) << what << ": threw '" << err.what() << "' but changed the estimator";
      return false;
    } catch (const std::exception& other) {
      ADD_FAILURE() << what << ": threw something other than a sextant::error: " << other.what();
      return false;
    }
    const Observable<Estimator> after(e);
    EXPECT_EQ(after.non_finite(), "") << what << " was accepted";
    // An accepted input must not brick the estimator: its estimates stay readable.
    EXPECT_EQ(after.estimate_error, "") << what << " was accepted, but then pose()/map() throw";
    return true;
  }
};

TYPED_TEST_SUITE_P(ExtremeInput);

TYPED_TEST_P(ExtremeInput, MeasurementsNearTheDoubleRange) {
  using W = typename TestFixture::World;
  for (double scale : {1e150, 1e300}) {
    auto e = this->make();
    this->warm_up(e);
    const std::string at = " at scale " + sci(scale);
    // known landmarks (1-4) and new ones (100-101) at once
    std::vector<typename TestFixture::Obs> z = this->observations(1, 4, scale);
    for (auto& o : this->observations(100, 2, scale)) z.push_back(o);
    this->finite_or_clean_error(e, [&] { e.update(z); }, "huge measurements" + at);
    this->finite_or_clean_error(e, [&] { e.update(this->observations(200, 1, scale)); }, "one huge new landmark" + at);
    // the estimator still takes ordinary input afterwards
    this->finite_or_clean_error(e, [&] { e.predict(W::control(1.0, 1.0), 0.1); }, "predict after" + at);
    this->finite_or_clean_error(e, [&] { e.update(this->observations(1, 4)); }, "ordinary update after" + at);
  }
}

TYPED_TEST_P(ExtremeInput, HugeTimeStep) {
  using W = typename TestFixture::World;
  for (double dt : {1e12, 1e300}) {
    auto e = this->make();
    this->warm_up(e);
    this->finite_or_clean_error(e, [&] { e.predict(W::control(1.0, 1.0), dt); }, "dt = " + sci(dt));
    this->finite_or_clean_error(e, [&] { e.update(this->observations(1, 4)); }, "update after dt = " + sci(dt));
  }
}

TYPED_TEST_P(ExtremeInput, ControlsNearTheDoubleRange) {
  if constexpr (!TestFixture::kHasControl) {
    GTEST_SKIP() << "this motion model takes no control";
  } else {
    using W = typename TestFixture::World;
    for (double scale : {1e100, 1e200, 1e300}) {
      auto e = this->make();
      this->warm_up(e);
      this->finite_or_clean_error(e, [&] { e.predict(W::control(scale, 1.0), 0.1); }, "control x " + sci(scale));
      this->finite_or_clean_error(e, [&] { e.update(this->observations(1, 4)); }, "update after a huge control");
    }
  }
}

TYPED_TEST_P(ExtremeInput, NearZeroAndHugeNoise) {
  using W = typename TestFixture::World;
  for (double sigma : {1e-160, 1e-100, 1e100, 1e150}) {
    const std::string at = "sigma = " + sci(sigma);
    std::optional<typename TestFixture::Estimator> e;
    try {
      e.emplace(this->make(sigma));
    } catch (const error&) {
      continue;  // rejecting such a model at construction is fine
    }
    for (int k = 0; k < 4; ++k) {
      if (!this->finite_or_clean_error(*e, [&] { e->predict(W::control(1.0, sigma), 0.1); }, "predict, " + at)) break;
      if (!this->finite_or_clean_error(*e, [&] { e->update(this->observations(1, 4 + k)); }, "update, " + at)) break;
    }
  }
}

TYPED_TEST_P(ExtremeInput, ThousandsOfNewLandmarksInOneUpdate) {
  auto e = this->make();
  this->warm_up(e);
  // A thousand, not more, to keep the default run short: SEIF makes every landmark of one update
  // active, and its sparsification then links all that it deactivates to each other (the robot's
  // information is passed on to them), so its cost is cubic in their number (docs/reliability.md).
  constexpr int kNew = 1000;
  if (this->finite_or_clean_error(e, [&] { e.update(this->observations(1000, kNew)); }, "1000 new landmarks")) {
    EXPECT_EQ(e.landmark_ids().size(), 4u + kNew);
    EXPECT_TRUE(e.has_landmark(1000 + kNew - 1));
  }
}

TYPED_TEST_P(ExtremeInput, RemoveALandmarkJustAddedThenObserveItAgain) {
  using W = typename TestFixture::World;
  auto e = this->make();
  this->warm_up(e);
  ASSERT_TRUE(this->finite_or_clean_error(e, [&] { e.update(this->observations(50, 1)); }, "add landmark 50"));
  ASSERT_TRUE(e.has_landmark(50));
  ASSERT_TRUE(this->finite_or_clean_error(e, [&] { e.remove_landmark(50); }, "remove landmark 50"));
  EXPECT_FALSE(e.has_landmark(50));
  for (const auto& m : e.map()) EXPECT_NE(m.id, 50u);
  // the same id, observed again on two later steps: one landmark, listed once
  for (int k = 0; k < 2; ++k) {
    e.predict(W::control(1.0, 1.0), 0.1);
    ASSERT_TRUE(this->finite_or_clean_error(e, [&] { e.update(this->observations(50, 1)); }, "observe 50 again"));
  }
  const auto ids = e.landmark_ids();
  EXPECT_EQ(std::count(ids.begin(), ids.end(), LandmarkId{50}), 1);
  const auto map = e.map();
  EXPECT_EQ(std::count_if(map.begin(), map.end(), [](const auto& m) { return m.id == 50u; }), 1);
  // and removing every landmark leaves a working estimator with an empty map
  for (LandmarkId id : e.landmark_ids()) e.remove_landmark(id);
  EXPECT_TRUE(e.map().empty());
  EXPECT_TRUE(this->finite_or_clean_error(e, [&] { e.update(this->observations(1, 2)); }, "update after removing all"));
}

REGISTER_TYPED_TEST_SUITE_P(ExtremeInput, MeasurementsNearTheDoubleRange, HugeTimeStep, ControlsNearTheDoubleRange,
                            NearZeroAndHugeNoise, ThousandsOfNewLandmarksInOneUpdate,
                            RemoveALandmarkJustAddedThenObserveItAgain);

/// Every back-end on one world.
template <class World>
using ExtremeCases = ::testing::Types<ExtremeCase<World, ExtremeEkf<EkfMode::batch>>, ExtremeCase<World, ExtremeEkf<EkfMode::sequential>>,
                                      ExtremeCase<World, ExtremeEkf<EkfMode::joseph>>, ExtremeCase<World, ExtremeSeif>,
                                      ExtremeCase<World, ExtremeGraph>, ExtremeCase<World, ExtremeFastSlam<FastSlamVersion::v1>>,
                                      ExtremeCase<World, ExtremeFastSlam<FastSlamVersion::v2>>>;

/// Names the instantiations after the back-end.
struct ExtremeCaseName {
  template <class Case>
  static std::string GetName(int) {
    std::string name = Case::Backend::kName;
    for (char& c : name)
      if (c == ' ' || c == '.') c = '_';
    return name;
  }
};

}  // namespace sextant::test
