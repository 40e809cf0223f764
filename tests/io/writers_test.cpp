#include <gtest/gtest.h>

#include "support/temp_path.hpp"

#include <filesystem>
#include <fstream>
#include <sstream>

#include "sextant/io/csv_writer.hpp"
#include "sextant/io/tum_writer.hpp"

namespace sextant::io {
namespace {

std::string read_all(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::stringstream buffer;
  buffer << in.rdbuf();
  return buffer.str();
}

TEST(CsvWriter, WritesHeaderAndRows) {
  const auto path = test::unique_temp_path("csv_writer_test.csv");
  {
    CsvWriter csv(path.string(), {"step", "error"});
    csv.row({1, 0.5});
    EXPECT_THROW(csv.row({1, 2, 3}), invalid_input_error);
  }
  EXPECT_EQ(read_all(path), "step,error\n1,0.5\n");
  EXPECT_THROW(CsvWriter("/nonexistent/dir/x.csv", {"a"}), error);
}

TEST(TumWriter, WritesPositionAndQuaternion) {
  const auto path = test::unique_temp_path("tum_writer_test.txt");
  write_tum(path.string(), {tum_pose_from_position(1.0, Eigen::Vector2d(2.0, 3.0)),
                            tum_pose_from_se2(2.0, 0.0, 0.0, std::numbers::pi)});
  std::istringstream lines(read_all(path));
  std::string first, second;
  std::getline(lines, first);
  std::getline(lines, second);
  EXPECT_EQ(first, "1 2 3 0 0 0 0 1");
  double t, x, y, z, qx, qy, qz, qw;
  std::istringstream(second) >> t >> x >> y >> z >> qx >> qy >> qz >> qw;
  EXPECT_NEAR(std::abs(qz), 1.0, 1e-12);
  EXPECT_NEAR(qw, 0.0, 1e-12);
}

}  // namespace
}  // namespace sextant::io
