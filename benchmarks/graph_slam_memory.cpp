// Peak memory of GraphSLAM on the first N poses of cityTrees10000 (N = 1000, 5000, 10000): each size
// runs in a child process (load, record, optimize, marginal covariances of every pose) and the
// parent reads the child's peak resident set (ru_maxrss) minus that of a child that only loads.
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <sextant/sextant.hpp>

namespace {

using namespace sextant;

void run_graph(const io::PlanarDataset& data, std::size_t poses) {
  if (poses == 0) return;
  PointInRobotFrame2D sensor;
  sensor.Q = data.landmark_cov;
  GraphSlam<Se2Odometry, PointInRobotFrame2D> graph{Se2Odometry{}, sensor,
                                                    {Eigen::Vector3d::Zero(), 1e-6 * Eigen::Matrix3d::Identity()}};
  graph.update(data.initial_observations);
  for (std::size_t k = 0; k + 1 < poses && k < data.steps.size(); ++k) {
    graph.predict(data.steps[k].control, data.steps[k].dt);
    graph.update(data.steps[k].observations);
  }
  graph.optimize();
  const auto trajectory = graph.trajectory();
  if (trajectory.size() != poses) std::_Exit(2);
}

/// Peak resident set of a child that loads the data and runs `poses` poses, in KiB.
long peak_kib(const std::string& path, std::size_t poses) {
  const pid_t child = fork();
  if (child == 0) {
    const auto data = io::read_isam_2d(path, io::IsamNoise::square_root_information);
    run_graph(data, poses);
    std::_Exit(0);
  }
  int status = 0;
  rusage usage{};
  wait4(child, &status, 0, &usage);
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) return -1;
  return usage.ru_maxrss;
}

}  // namespace

int main() {
  const std::string path = std::string(SEXTANT_SHARED_DATA_DIR) + "/city_trees/cityTrees10000.txt";
  if (!std::filesystem::exists(path)) {
    std::printf("data set not found: %s\n", path.c_str());
    return 0;
  }
  const long baseline = peak_kib(path, 0);
  std::printf("| poses | peak memory above loading [MiB] | per pose [KiB] |\n|---|---|---|\n");
  for (std::size_t poses : {1000u, 5000u, 10000u}) {
    const long peak = peak_kib(path, poses);
    const double above = static_cast<double>(peak - baseline);
    std::printf("| %zu | %.1f | %.2f |\n", poses, above / 1024.0, above / static_cast<double>(poses));
  }
  std::printf("(baseline: a process that only loads the file, %.1f MiB)\n", static_cast<double>(baseline) / 1024.0);
  return 0;
}
