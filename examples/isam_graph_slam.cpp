// GraphSLAM on a planar data set in the iSAM text format (cityTrees10000, Victoria Park, ...):
// reads it, optimizes, prints the summary and writes the optimized poses and landmarks as CSV
// (examples/plot_planar_map.py turns them into a PNG).
#include <CLI/CLI.hpp>
#include <cstdio>
#include <filesystem>
#include <sextant/io/isam_dataset.hpp>
#include <sextant/sextant.hpp>

int main(int argc, char** argv) {
  using namespace sextant;
  CLI::App app{"sextant: GraphSLAM on an iSAM-format planar data set"};
  std::string path, noise = "auto", out_dir;
  GraphOptions options;
  app.add_option("file", path, "data file (EDGE2/ODOMETRY and LANDMARK records)")->required()->check(CLI::ExistingFile);
  app.add_option("--noise", noise,
                 "noise values: sqrt (square-root information, iSAM), cov (covariance, GTSAM) or auto (read off the first "
                 "odometry record: EDGE2 sqrt, ODOMETRY cov)")
      ->check(CLI::IsMember({"auto", "sqrt", "cov"}))
      ->capture_default_str();
  app.add_option("--window", options.window, "windowed initialization: steps per sub-part (0 = dead reckoning)")
      ->capture_default_str();
  app.add_option("--max-iterations", options.max_iterations, "Gauss-Newton iterations")->check(CLI::Range(1, 10000))->capture_default_str();
  app.add_option("--out", out_dir, "directory for poses.csv and landmarks.csv");
  CLI11_PARSE(app, argc, argv);
  try {
    const io::IsamNoise form = noise == "auto" ? io::detect_isam_noise(path)
                               : noise == "cov"  ? io::IsamNoise::covariance
                                                 : io::IsamNoise::square_root_information;
    const auto data = io::read_isam_2d(path, form);
    PointInRobotFrame2D sensor;
    sensor.Q = data.landmark_cov;
    GraphSlam<Se2Odometry, PointInRobotFrame2D> graph{Se2Odometry{}, sensor,
                                                      {Eigen::Vector3d::Zero(), 1e-6 * Eigen::Matrix3d::Identity()}, options};
    graph.update(data.initial_observations);
    for (const auto& step : data.steps) {
      graph.predict(step.control, step.dt);
      graph.update(step.observations);
    }
    const auto summary = graph.optimize();
    std::printf("%s: %zu poses, %zu landmarks; %d iterations, %s; chi2 %.6g -> %.6g; linearize %.3f s, eliminate %.3f s, "
                "solve %.3f s (%s)\n",
                path.c_str(), graph.num_poses(), graph.num_landmarks(), summary.iterations,
                summary.converged ? "converged" : "NOT converged", summary.cost.front(),
                summary.cost[static_cast<std::size_t>(summary.best_iteration)],
                summary.seconds_linearize, summary.seconds_eliminate, summary.seconds_solve, SparseCholesky::backend());
    if (summary.damped_from >= 0)
      std::printf("Gauss-Newton's chi2 rose at iteration %d: that step was undone and the steps after it damped "
                  "(Levenberg-Marquardt)\n", summary.damped_from);
    if (summary.best_iteration != summary.iterations)
      std::printf("the estimate is iteration %d's, the lowest chi2; the last one ended at %.6g\n", summary.best_iteration,
                  summary.cost.back());
    if (!out_dir.empty()) {
      std::filesystem::create_directories(out_dir);
      io::CsvWriter poses((std::filesystem::path(out_dir) / "poses.csv").string(), {"x", "y", "heading"});
      for (const auto& p : graph.pose_means()) poses.row({p(0), p(1), p(2)});
      io::CsvWriter landmarks((std::filesystem::path(out_dir) / "landmarks.csv").string(),
                              {"id", "x", "y", "var_x", "cov_xy", "var_y"});
      for (const auto& l : graph.map())
        landmarks.row({static_cast<double>(l.id), l.mean(0), l.mean(1), l.cov(0, 0), l.cov(0, 1), l.cov(1, 1)});
      std::printf("wrote %s/poses.csv and landmarks.csv\n", out_dir.c_str());
    }
    return summary.converged ? 0 : 3;
  } catch (const sextant::error& e) {
    std::fprintf(stderr, "sextant-isam: %s\n", e.what());
    return 1;
  }
}
