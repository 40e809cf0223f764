// MRPT's kf-slam_6D_demo_DA.rawlog: a 6D robot among 3D landmarks whose measurements carry no ids
// (landmarkID = -1). Every back-end that can associate runs it; the EKF with JCBB against MRPT's
// own kf-slam with EKF-SLAM_6D_test_datassoc.ini (full EKF, JCBB, chi-square 0.99) on the same log.
#include <gtest/gtest.h>

#include <filesystem>
#include <set>
#include <numbers>

#include "mrpt/mrpt_demo_data.hpp"
#include "sextant/backends/ekf_slam.hpp"
#include "sextant/backends/fast_slam.hpp"
#include "sextant/backends/seif_slam.hpp"
#include "sextant/core/chi_square.hpp"
#include "sextant/eval/experiment.hpp"
#include "sextant/eval/particle_association.hpp"
#include "sextant/eval/withheld_ids.hpp"
#include "sextant/mrpt/rawlog.hpp"
#include "support/mrpt_kf_slam.hpp"

namespace sextant::mrpt_io {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;
const std::string kDatassocIni = "/usr/share/mrpt/config_files/kf-slam/EKF-SLAM_6D_test_datassoc.ini";

/// Mean distance of each mapped landmark to its nearest true landmark: the one metric that needs no
/// ids, so MRPT's map (which has none) and ours are scored alike.
template <class Truth, class Positions>
double mean_nearest_truth_error(const Truth& truth, const Positions& positions) {
  double sum = 0.0;
  for (const Eigen::Vector3d& p : positions) {
    double nearest = std::numeric_limits<double>::infinity();
    for (const auto& [id, m] : truth) nearest = std::min(nearest, (p - m).norm());
    sum += nearest;
  }
  return positions.empty() ? std::numeric_limits<double>::infinity() : sum / static_cast<double>(positions.size());
}

template <class Map>
std::vector<Eigen::Vector3d> positions_of(const Map& map) {
  std::vector<Eigen::Vector3d> out;
  for (const auto& landmark : map) out.push_back(landmark.mean);
  return out;
}

class KfSlamDaDemo : public ::testing::Test {
 protected:
  void SetUp() override {
    SEXTANT_REQUIRE_MRPT_DEMO("kf-slam_6D_demo_DA.rawlog");
    if (!std::filesystem::exists(kDatassocIni)) GTEST_SKIP() << kDatassocIni << " not found (mrpt-common)";
    path = testing::mrpt_demo("kf-slam_6D_demo_DA.rawlog");
    RawlogOptions options;  // the noise the ini gives MRPT's filter
    options.std_range = 0.05;
    options.std_yaw = 0.5 * kDeg;
    options.std_pitch = 0.5 * kDeg;
    data = read_rawlog_3d(path, options);
    inferred = attach_ground_truth(data, *find_ground_truth(path));
  }
  std::string path;
  RawlogDataset3D data;
  std::optional<io::InferredIds> inferred;
};

TEST_F(KfSlamDaDemo, IdsFromTheGroundTruthAreClearCut) {
  ASSERT_TRUE(inferred);
  EXPECT_EQ(data.ids, io::LandmarkIds::from_ground_truth);
  EXPECT_GT(inferred->observations, 0u);
  std::printf("%zu measurements; worst NIS to the chosen landmark %.2f; smallest ratio of the second-best NIS to it %.1f\n",
              inferred->observations, inferred->worst_nis, inferred->smallest_margin);
  // Each measurement is within the 0.9999 chi-square bound of its landmark, and no other landmark
  // comes within 10x of that NIS: the inferred ids are the simulator's.
  EXPECT_LT(inferred->worst_nis, chi_square_quantile(3, 0.9999));
  EXPECT_GT(inferred->smallest_margin, 10.0);
}

TEST_F(KfSlamDaDemo, EkfWithJcbbMapsAtLeastAsWellAsMrptKfSlamWithItsDatassocIni) {
  const auto mrpt_map = test::run_mrpt_kf_slam_3d(test::read_mrpt_pairs(path), kDatassocIni);
  const double mrpt_error = mean_nearest_truth_error(data.true_landmarks, mrpt_map);

  EkfSlam<Se3Odometry, RangeBearing3D> ekf(data.motion, data.sensor, data.prior);
  eval::WithheldIds withheld(ekf, data.sensor, {.method = AssociationMethod::joint_compatibility});
  const auto run = eval::evaluate_run(withheld, data, 3);
  const double ekf_error = mean_nearest_truth_error(data.true_landmarks, positions_of(ekf.map()));
  std::printf("landmarks mapped: sextant EKF+JCBB %zu, MRPT kf-slam %zu (truth %zu); mean error to the nearest true "
              "landmark: %.4f m vs %.4f m; association precision %.4f recall %.4f\n",
              ekf.map().size(), mrpt_map.size(), data.true_landmarks.size(), ekf_error, mrpt_error,
              withheld.score().precision(), withheld.score().recall());
  // Same algorithm (full EKF, JCBB at 0.99, same noise): the map must be no worse than MRPT's, and
  // every mapped landmark a distinct true one.
  EXPECT_LE(ekf_error, mrpt_error);
  EXPECT_EQ(withheld.score().wrong(), 0u);
  EXPECT_EQ(withheld.score().duplicates(), 0u);
  EXPECT_EQ(run.map_error.size(), ekf.map().size());
}

TEST_F(KfSlamDaDemo, SeifAndFastSlamAssociateToo) {
  EkfSlam<Se3Odometry, RangeBearing3D> ekf(data.motion, data.sensor, data.prior);
  eval::WithheldIds ekf_withheld(ekf, data.sensor, {.method = AssociationMethod::joint_compatibility});
  const double ekf_aligned = eval::mean(eval::evaluate_run(ekf_withheld, data, 3).map_error_aligned);
  // SEIF with 8 active landmarks: sparsification makes its marginals overconfident, yet every
  // pairing must be right, and the map's shape (after rigid alignment; sparsification loses mostly
  // the global placement) within 2x of the EKF's, the margin the demo with ids uses (rawlog_test.cpp).
  SeifSlam<Se3Odometry, RangeBearing3D> seif(data.motion, data.sensor, data.prior, {.max_active = 8});
  eval::WithheldIds seif_withheld(seif, data.sensor, {.method = AssociationMethod::joint_compatibility});
  const auto seif_run = eval::evaluate_run(seif_withheld, data, 3);
  EXPECT_EQ(seif_withheld.score().wrong(), 0u);
  EXPECT_EQ(seif_withheld.score().duplicates(), 0u);
  EXPECT_LT(eval::mean(seif_run.map_error_aligned), 2.0 * ekf_aligned);
  // FastSLAM 2.0, per-particle maximum likelihood (new landmark beyond the 3-dof 0.9999 quantile),
  // against the same filter given the true ids, run here: every true landmark mapped, at most one
  // duplicate in the best particle (one in twenty), and the aligned map within 2x of the run with
  // ids (a duplicate splits one landmark's measurements in two).
  const FastSlamOptions options{.particles = 100, .resample_threshold = 0.1,
                                .new_landmark_nis = chi_square_quantile(3, 0.9999)};
  FastSlam<Se3Odometry, RangeBearing3D> with_ids(data.motion, data.sensor, data.prior, options);
  const double ids_aligned = eval::mean(eval::evaluate_run(with_ids, data, 3).map_error_aligned);
  FastSlam<Se3Odometry, RangeBearing3D> fast(data.motion, data.sensor, data.prior, options);
  eval::ParticleAssociation fast_withheld(fast);
  const auto fast_run = eval::evaluate_run(fast_withheld, data, 3);
  std::set<LandmarkId> mapped;
  for (const auto& landmark : fast_withheld.map()) mapped.insert(landmark.id);
  EXPECT_EQ(mapped.size(), data.true_landmarks.size());
  EXPECT_LE(fast.map().size(), data.true_landmarks.size() + 1);
  EXPECT_TRUE(fast.pose().mean.allFinite());
  EXPECT_LT(eval::mean(fast_run.map_error_aligned), 2.0 * ids_aligned);
  // Scored step by step by the particle most likely at the step: the ids are clear-cut here (the
  // test above), so no pairing of it is wrong, and it paired re-observations (correct > 0).
  const auto& fast_score = fast_withheld.score();
  EXPECT_EQ(fast_score.wrong(), 0u);
  EXPECT_GT(fast_score.correct(), 0u);
  std::printf("aligned map error [m]: EKF+JCBB %.4f, SEIF 8 active+JCBB %.4f, FastSLAM 2.0 per-particle %.4f (with the "
              "true ids %.4f); FastSLAM landmarks %zu; its most likely particle's association step by step: precision "
              "%.4f, recall %.4f, %zu duplicates\n",
              ekf_aligned, eval::mean(seif_run.map_error_aligned), eval::mean(fast_run.map_error_aligned), ids_aligned,
              fast.map().size(), fast_score.precision(), fast_score.recall(), fast_score.duplicates());
}

}  // namespace
}  // namespace sextant::mrpt_io
