#include "sextant/mrpt/rawlog.hpp"

#include <gtest/gtest.h>

#include "mrpt/mrpt_demo_data.hpp"
#include "sextant/backends/ekf_slam.hpp"
#include "sextant/eval/experiment.hpp"

namespace sextant::mrpt_io {
namespace {

TEST(KfSlamDemo, EkfMapError) {
  SEXTANT_REQUIRE_MRPT_DEMO("kf-slam_demo.rawlog");
  RawlogOptions o; if (getenv("SR")) o.std_range = atof(getenv("SR"));
  auto data = read_rawlog_2d(testing::mrpt_demo("kf-slam_demo.rawlog"), o);
  attach_ground_truth(data, *find_ground_truth(data.path));
  EkfSlam<Se2Odometry, RangeBearing2D> ekf(data.motion, data.sensor, data.prior);
  const auto run = eval::evaluate_run(ekf, data, 2);
  std::printf("steps %zu landmarks %zu map mean error %.6f m, pose MAE %.6f\n", data.steps.size(), ekf.map().size(),
              eval::mean(run.map_error), eval::mean(run.pose_error));
}

}  // namespace
}  // namespace sextant::mrpt_io
