#include "sextant/io/visual_inertial_npz.hpp"

#include <gtest/gtest.h>
#include <sys/resource.h>
#include <zip.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <algorithm>
#include <map>

#include "support/shared_data.hpp"
#include "support/temp_path.hpp"

namespace sextant::io {
namespace {

/// .npy bytes (version 1.0) of `values` with the given dtype string, order flag and shape; values are
/// written as the dtype says (f8, f4, i8, i4), in the order given.
std::string npy(const std::vector<double>& values, const std::string& shape, const std::string& descr = "<f8",
                bool fortran = false) {
  std::string header = "{'descr': '" + descr + "', 'fortran_order': " + (fortran ? "True" : "False") +
                       ", 'shape': " + shape + ", }";
  while ((10 + header.size() + 1) % 64 != 0) header += ' ';
  header += '\n';
  std::string out("\x93NUMPY\x01\x00", 8);
  out += static_cast<char>(header.size() & 0xff);
  out += static_cast<char>(header.size() >> 8);
  out += header;
  for (const double v : values) {
    char bytes[8];
    std::size_t n = 8;
    if (descr == "<f8") {
      std::memcpy(bytes, &v, 8);
    } else if (descr == "<f4") {
      const float f = static_cast<float>(v);
      std::memcpy(bytes, &f, n = 4);
    } else if (descr == "<i8") {
      const std::int64_t i = static_cast<std::int64_t>(v);
      std::memcpy(bytes, &i, 8);
    } else {
      const std::int32_t i = static_cast<std::int32_t>(v);
      std::memcpy(bytes, &i, n = 4);
    }
    out.append(bytes, n);
  }
  return out;
}

class NpzFiles : public ::testing::Test {
 protected:
  std::filesystem::path dir =
      test::unique_temp_path(std::string("npz_") + ::testing::UnitTest::GetInstance()->current_test_info()->name());
  void SetUp() override { std::filesystem::create_directories(dir); }
  void TearDown() override { std::filesystem::remove_all(dir); }

  /// Writes a .npz of the given entries (key -> .npy bytes), stored without compression (deflated
  /// with `method` ZIP_CM_DEFLATE).
  std::string write_npz(const std::string& name, const std::map<std::string, std::string>& entries,
                        zip_int32_t method = ZIP_CM_STORE) {
    const auto path = (dir / name).string();
    int error = 0;
    zip_t* archive = zip_open(path.c_str(), ZIP_CREATE | ZIP_TRUNCATE, &error);
    EXPECT_NE(archive, nullptr);
    for (const auto& [key, bytes] : entries) {
      zip_source_t* source = zip_source_buffer(archive, bytes.data(), bytes.size(), 0);
      const auto index = zip_file_add(archive, (key + ".npy").c_str(), source, ZIP_FL_OVERWRITE);
      EXPECT_GE(index, 0);
      zip_set_file_compression(archive, static_cast<zip_uint64_t>(index), method, 0);
    }
    EXPECT_EQ(zip_close(archive), 0);  // the buffers must live until here
    return path;
  }

  /// A small valid data set: 3 frames, 2 landmarks; landmark 0 seen in frames 0 and 2, landmark 1
  /// in frame 1 and partly (one pixel -1) in frame 2.
  std::map<std::string, std::string> small_dataset() {
    const std::size_t M = 2, T = 3;
    std::vector<double> features(4 * M * T, -1.0);
    const auto set = [&](std::size_t m, std::size_t k, std::array<double, 4> z) {
      for (std::size_t c = 0; c < 4; ++c) features[(c * M + m) * T + k] = z[c];
    };
    set(0, 0, {700, 200, 650, 200});
    set(0, 2, {710, 201, 655, 201});
    set(1, 1, {300, 100, 280, 100});
    set(1, 2, {310, -1, 290, 101});
    return {{"time_stamps", npy({10.0, 10.1, 10.25}, "(1, 3)")},
            {"linear_velocity", npy({1, 2, 3, 4, 5, 6, 7, 8, 9}, "(3, 3)")},
            {"angular_velocity", npy({0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9}, "(3, 3)")},
            {"features", npy(features, "(4, 2, 3)")},
            {"K", npy({700, 0, 600, 0, 710, 180, 0, 0, 1}, "(3, 3)")},
            {"b", npy({0.5}, "()")},
            {"imu_T_cam", npy({0, 0, 1, 1.5, -1, 0, 0, 0.1, 0, -1, 0, -0.6, 0, 0, 0, 1}, "(4, 4)")}};
  }

  std::string error_of(const std::string& path) {
    try {
      (void)read_visual_inertial_npz(path);
    } catch (const parse_error& e) {
      return e.what();
    }
    ADD_FAILURE() << path << " was read without an error";
    return {};
  }
};

/// Sets the uncompressed size the archive states for `entry` (local and central header alike, so
/// that libzip's consistency check passes): an entry that would inflate to `size` bytes.
void state_uncompressed_size(const std::string& path, const std::string& entry, std::uint32_t size) {
  std::string bytes;
  {
    std::ifstream in(path, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), {});
  }
  auto put = [&](std::size_t at) {
    for (int b = 0; b < 4; ++b) bytes[at + b] = static_cast<char>((size >> (8 * b)) & 0xff);
  };
  int patched = 0;
  for (std::size_t at = bytes.find("PK\x03\x04"); at != std::string::npos; at = bytes.find("PK\x03\x04", at + 4))
    if (bytes.compare(at + 30, entry.size(), entry) == 0) put(at + 22), ++patched;
  for (std::size_t at = bytes.find("PK\x01\x02"); at != std::string::npos; at = bytes.find("PK\x01\x02", at + 4))
    if (bytes.compare(at + 46, entry.size(), entry) == 0) put(at + 24), ++patched;
  ASSERT_EQ(patched, 2) << "local and central header of " << entry;
  std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
}

TEST_F(NpzFiles, AnEntryBeyondTheSizeLimitIsRefusedBeforeAByteIsInflated) {
  // Issue 36: a 5.6 MB .npz whose features.npy deflates to 3.8 GB was inflated whole (peak RSS
  // 3.8 GB), one of 12.8 GB ended in std::bad_alloc naming no file. The archive states each entry's
  // uncompressed size, and libzip never inflates past it: that statement is checked first.
  auto entries = small_dataset();
  entries["features"] = npy(std::vector<double>(4 * 2 * 3, -1.0), "(4, 59375000, 2)");  // 3.8 GB declared
  const auto path = write_npz("bomb.npz", entries, ZIP_CM_DEFLATE);
  state_uncompressed_size(path, "features.npy", 3'800'000'000u);
  const std::string message = error_of(path);
  EXPECT_NE(message.find(path + ": key 'features': 3800000000 bytes once uncompressed"), std::string::npos) << message;
  EXPECT_NE(message.find("more than the reader's limit of 1073741824 bytes"), std::string::npos) << message;
  rusage usage{};
  ::getrusage(RUSAGE_SELF, &usage);
  EXPECT_LT(usage.ru_maxrss, 200 * 1024) << "peak RSS in kB";  // the whole test process, this test alone under ctest
  // An entry of the stated size within the limit reads as before.
  EXPECT_NO_THROW(NpzFile(write_npz("fine.npz", small_dataset(), ZIP_CM_DEFLATE)).array("features"));
}

TEST(Npy, ReadsEveryDtypeInCAndFortranOrder) {
  for (const std::string descr : {"<f8", "<f4", "<i8", "<i4"}) {
    const auto c = read_npy(npy({1, 2, 3, 4, 5, 6}, "(2, 3)", descr), "c");
    EXPECT_EQ(c.shape, (std::vector<std::size_t>{2, 3}));
    EXPECT_EQ(c.values, (std::vector<double>{1, 2, 3, 4, 5, 6})) << descr;
    EXPECT_EQ(c.at({1, 0}), 4.0);
    // The same 2x3 matrix stored column by column.
    const auto f = read_npy(npy({1, 4, 2, 5, 3, 6}, "(2, 3)", descr, true), "f");
    EXPECT_EQ(f.values, c.values) << descr;
  }
  const auto scalar = read_npy(npy({0.6}, "()"), "b");
  EXPECT_TRUE(scalar.shape.empty());
  EXPECT_EQ(scalar.values, std::vector<double>{0.6});
  EXPECT_EQ(read_npy(npy({1, 2, 3}, "(3,)"), "v").shape, std::vector<std::size_t>{3});
  // Three dimensions in Fortran order: a(i, j, k) stored with i fastest.
  std::vector<double> fortran;
  for (int k = 0; k < 4; ++k)
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 2; ++i) fortran.push_back(100 * i + 10 * j + k);
  const auto a = read_npy(npy(fortran, "(2, 3, 4)", "<f8", true), "a");
  EXPECT_EQ(a.at({1, 2, 3}), 123.0);
  EXPECT_EQ(a.at({0, 1, 2}), 12.0);
}

TEST(Npy, MalformedArraysAreErrorsNamingTheArray) {
  const auto error = [](const std::string& bytes) {
    try {
      (void)read_npy(bytes, "FILE: key 'x'");
    } catch (const parse_error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const std::string good = npy({1, 2, 3, 4}, "(2, 2)");
  EXPECT_NE(error("PK\x03\x04 not npy").find("FILE: key 'x': not a .npy array"), std::string::npos);
  EXPECT_NE(error(npy({1, 2}, "(2,)", ">f8")).find("dtype '>f8' is not supported"), std::string::npos);
  EXPECT_NE(error(npy({1, 2}, "(2,)", "<c16")).find("dtype '<c16' is not supported"), std::string::npos);
  EXPECT_NE(error(good.substr(0, good.size() - 3)).find("truncated .npy data"), std::string::npos);
  EXPECT_NE(error(good.substr(0, 20)).find("truncated .npy header"), std::string::npos);
  EXPECT_NE(error(npy({}, "(4000000000, 4000000000)")).find("more than"), std::string::npos);
  EXPECT_NE(error(npy({1}, "(a,)")).find("not a non-negative integer"), std::string::npos);
  std::string no_shape = good;
  no_shape.replace(no_shape.find("'shape'"), 7, "'shope'");
  EXPECT_NE(error(no_shape).find("no 'shape'"), std::string::npos);
}

TEST_F(NpzFiles, ReadsStepsObservationsCalibrationAndExtrinsic) {
  const auto data = read_visual_inertial_npz(write_npz("small.npz", small_dataset()));
  ASSERT_EQ(data.time_stamps.size(), 3u);
  ASSERT_EQ(data.steps.size(), 2u);
  EXPECT_EQ(data.landmark_count, 2u);
  EXPECT_EQ(data.observation_count, 3u);
  EXPECT_EQ(data.incomplete_observations, 1u);  // landmark 1 in frame 2 has vL = -1
  ASSERT_EQ(data.first_observations.size(), 1u);
  EXPECT_EQ(data.first_observations[0].landmark_id, 0u);
  EXPECT_EQ(data.first_observations[0].z, Eigen::Vector4d(700, 200, 650, 200));
  EXPECT_NEAR(data.steps[0].dt, 0.1, 1e-12);
  EXPECT_NEAR(data.steps[1].dt, 0.15, 1e-12);
  // Step 1 (frame 1 -> 2) holds the velocity sampled at frame 1: column 1 of (3, T).
  se3::Vector6d u1;
  u1 << 2, 5, 8, 0.2, 0.5, 0.8;
  EXPECT_EQ(data.steps[1].control, u1);
  ASSERT_EQ(data.steps[1].observations.size(), 1u);
  EXPECT_EQ(data.steps[1].observations[0].landmark_id, 0u);
  EXPECT_EQ(data.steps[0].observations[0].landmark_id, 1u);
  EXPECT_EQ(data.calibration.fy, 710.0);
  EXPECT_EQ(data.calibration.cy, 180.0);
  EXPECT_EQ(data.calibration.baseline, 0.5);
  EXPECT_EQ(data.extrinsic_key, "imu_T_cam");
  // imu_T_cam puts the camera at (1.5, 0.1, -0.6) in the IMU frame: cam_T_imu maps it to the origin.
  EXPECT_TRUE((data.cam_T_imu * Eigen::Vector4d(1.5, 0.1, -0.6, 1.0)).isApprox(Eigen::Vector4d(0, 0, 0, 1), 1e-12));
}

TEST_F(NpzFiles, AnImuTCamInForwardRightDownAxesIsRebasedOntoTheVelocitiesAxes) {
  // The same camera mounting given in x-forward, y-right, z-down IMU axes (as 03.npz gives it):
  // camera x (right) along IMU +y, camera y (down) along IMU +z, the camera at (1.5, -0.1, 0.6).
  auto entries = small_dataset();
  entries["imu_T_cam"] = npy({0, 0, 1, 1.5, 1, 0, 0, -0.1, 0, 1, 0, 0.6, 0, 0, 0, 1}, "(4, 4)");
  const auto path = write_npz("right_down.npz", entries);
  const auto rebased = read_visual_inertial_npz(path);
  const auto flu = read_visual_inertial_npz(write_npz("small.npz", small_dataset()));
  EXPECT_TRUE(rebased.cam_T_imu.isApprox(flu.cam_T_imu, 1e-12)) << rebased.cam_T_imu << "\n\n" << flu.cam_T_imu;
  const auto as_stored = read_visual_inertial_npz(path, {.rebase_forward_right_down_extrinsic = false});
  EXPECT_TRUE((as_stored.cam_T_imu * Eigen::Vector4d(1.5, -0.1, 0.6, 1.0)).isApprox(Eigen::Vector4d(0, 0, 0, 1), 1e-12));
}

TEST_F(NpzFiles, ImplausibleVelocitiesAreUsedAndListedWithFileAndFrame) {
  // Issue 36: a legal but implausible velocity (500 m/s, 20 rad/s) was integrated without a word.
  EXPECT_EQ(read_visual_inertial_npz(write_npz("small.npz", small_dataset())).implausible.count, 0u);
  auto entries = small_dataset();
  entries["linear_velocity"] = npy({1, 2, 3, 4, 500, 6, 7, 8, 9}, "(3, 3)");
  entries["angular_velocity"] = npy({20, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9}, "(3, 3)");
  const auto path = write_npz("fast.npz", entries);
  const auto data = read_visual_inertial_npz(path);
  EXPECT_EQ(data.steps[1].control(1), 500.0);  // used as given
  const auto warnings = data.implausible.warnings();
  ASSERT_EQ(warnings.size(), 2u);
  EXPECT_EQ(warnings[0], "warning: " + path + ": frame 0: angular velocity 20 rad/s is beyond the plausible 6.28319 rad/s (used as given)");
  EXPECT_EQ(warnings[1], "warning: " + path + ": frame 1: linear velocity 500 m/s is beyond the plausible 100 m/s (used as given)");
}

TEST_F(NpzFiles, ReadsTheOtherKeySpellingsAndTheCamTImuConvention) {
  auto entries = small_dataset();
  entries["rotational_velocity"] = entries["angular_velocity"];
  entries.erase("angular_velocity");
  // cam_T_imu as 0027_*.npz store it: rotation IMU -> camera axes, translation the camera position.
  entries["cam_T_imu"] = npy({0, -1, 0, 1.5, 0, 0, -1, 0.1, 1, 0, 0, -0.6, 0, 0, 0, 1}, "(4, 4)");
  entries.erase("imu_T_cam");
  const auto path = write_npz("other.npz", entries);
  const auto data = read_visual_inertial_npz(path);
  EXPECT_EQ(data.extrinsic_key, "cam_T_imu");
  EXPECT_EQ(data.steps[0].control(3), 0.1);
  EXPECT_TRUE((data.cam_T_imu * Eigen::Vector4d(1.5, 0.1, -0.6, 1.0)).isApprox(Eigen::Vector4d(0, 0, 0, 1), 1e-12));
  // Read as a proper transform, the same key moves the camera elsewhere.
  const auto proper = read_visual_inertial_npz(path, {.cam_T_imu_translation_is_camera_position = false});
  EXPECT_TRUE((se3::translation(proper.cam_T_imu) - Eigen::Vector3d(1.5, 0.1, -0.6)).isZero(0.0));
}

TEST_F(NpzFiles, MalformedDataSetsAreErrorsNamingFileAndKey) {
  const auto path_with = [&](const std::string& name, const std::string& key, const std::string& bytes) {
    auto entries = small_dataset();
    if (bytes.empty())
      entries.erase(key);
    else
      entries[key] = bytes;
    return write_npz(name, entries);
  };
  const auto expect = [&](const std::string& path, const std::string& part) {
    const auto message = error_of(path);
    EXPECT_NE(message.find(path), std::string::npos) << message;
    EXPECT_NE(message.find(part), std::string::npos) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  };
  expect(path_with("no_k.npz", "K", ""), "key 'K' is missing");
  expect(path_with("no_w.npz", "angular_velocity", ""), "'rotational_velocity') is missing");
  expect(path_with("no_extrinsic.npz", "imu_T_cam", ""), "key 'imu_T_cam' (or 'cam_T_imu') is missing");
  expect(path_with("k_shape.npz", "K", npy({1, 2, 3, 4}, "(2, 2)")), "key 'K': shape (2,2,) where (3,3,) was expected");
  expect(path_with("v_shape.npz", "linear_velocity", npy({1, 2, 3}, "(3, 1)")), "key 'linear_velocity': shape");
  expect(path_with("k_dtype.npz", "K", npy({1, 2}, "(2,)", "<u2")), "key 'K': dtype '<u2' is not supported");
  expect(path_with("dt.npz", "time_stamps", npy({10.0, 10.1, 10.1}, "(1, 3)")), "frame 2 is not later than frame 1");
  expect(path_with("nan.npz", "b", npy({std::nan("")}, "()")), "key 'b': holds a NaN");
  // Issue 36: time stamps that jump by 1e9 s and values too large for the estimators' arithmetic were
  // reported by a filter ("innovation covariance of landmark 18 is not positive definite").
  expect(path_with("jump.npz", "time_stamps", npy({10.0, 10.1, 1e9}, "(1, 3)")),
         "key 'time_stamps': frame 2 is 999999989.900000 s after frame 1, more than 60.000000 s");
  expect(path_with("huge.npz", "linear_velocity", npy({1, 2, 3, 4, 1e308, 6, 7, 8, 9}, "(3, 3)")),
         "key 'linear_velocity': holds 1e+308, beyond +-1e12");
  expect(path_with("baseline.npz", "b", npy({-0.5}, "()")), "the baseline must be positive");
  expect(path_with("rigid.npz", "imu_T_cam", npy({2, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}, "(4, 4)")),
         "not a rigid transform");
  expect(path_with("features.npz", "features", npy(std::vector<double>(24, -1.0), "(4, 2, 3)", "<f8", false).substr(0, 200)),
         "key 'features': truncated .npy data");
  auto both = small_dataset();
  both["cam_T_imu"] = both["imu_T_cam"];
  expect(write_npz("both.npz", both), "has both 'imu_T_cam' and 'cam_T_imu'");
}

TEST_F(NpzFiles, DamagedArchivesAreErrorsNamingTheFile) {
  // Issue 36: a directory where a file is expected said "Operation not supported".
  std::filesystem::create_directories(dir / "folder.npz");
  EXPECT_NE(error_of((dir / "folder.npz").string()).find("folder.npz: is a directory, not a file"), std::string::npos);
  const auto good = write_npz("good.npz", small_dataset());
  std::ifstream in(good, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto write = [&](const std::string& name, const std::string& content) {
    const auto path = (dir / name).string();
    std::ofstream(path, std::ios::binary) << content;
    return path;
  };
  const auto truncated = write("truncated.npz", bytes.substr(0, bytes.size() / 2));
  EXPECT_NE(error_of(truncated).find(truncated + ": not a readable .npz (zip) file"), std::string::npos);
  const auto text = write("text.npz", "time_stamps,K\n1,2\n");
  EXPECT_NE(error_of(text).find(text + ": not a readable .npz (zip) file"), std::string::npos);
  // A flipped byte inside the stored K array: the entry's CRC no longer matches.
  std::string flipped = bytes;
  const auto K_data = flipped.find("'fortran_order': False, 'shape': (3, 3)");
  ASSERT_NE(K_data, std::string::npos);
  const auto K_values = flipped.find('\n', K_data) + 1 + 8;  // inside the second value of K (0.0)
  flipped[K_values] ^= 0x40;
  const auto corrupt = write("crc.npz", flipped);
  const auto message = error_of(corrupt);
  EXPECT_NE(message.find(corrupt + ": key '"), std::string::npos) << message;
  EXPECT_NE(message.find("corrupt entry"), std::string::npos) << message;
  EXPECT_NE(error_of((dir / "absent.npz").string()).find("absent.npz: cannot open file (no such file)"), std::string::npos);
}

TEST(VisualInertialNpz, ReadsTheSeedsDataSets) {
  const auto path_03 = test::shared_data("ece276a/03.npz");
  SEXTANT_REQUIRE_DATA(path_03);
  const auto data = read_visual_inertial_npz(path_03);
  EXPECT_EQ(data.time_stamps.size(), 1010u);
  EXPECT_EQ(data.landmark_count, 5105u);
  EXPECT_EQ(data.extrinsic_key, "imu_T_cam");
  EXPECT_EQ(data.calibration.baseline, 0.6);
  const double per_frame = static_cast<double>(data.observation_count) / 1010.0;
  EXPECT_GT(per_frame, 50.0);  // ../shared/data/README.md: about 66 per frame
  EXPECT_LT(per_frame, 80.0);
  for (const auto& step : data.steps) {
    EXPECT_GT(step.dt, 0.0);
    for (const auto& o : step.observations) ASSERT_LT(o.landmark_id, 5105u);
  }
  // The camera looks forward: the IMU's +x axis is the camera's +z (optical axis), within 10 deg.
  const Eigen::Vector3d forward = se3::rotation(data.cam_T_imu) * Eigen::Vector3d::UnitX();
  EXPECT_GT(forward.z(), std::cos(10.0 * std::numbers::pi / 180.0));

  const auto path_27 = test::shared_data("ece276a/0027_clean.npz");
  SEXTANT_REQUIRE_DATA(path_27);
  const auto clean = read_visual_inertial_npz(path_27);
  EXPECT_EQ(clean.extrinsic_key, "cam_T_imu");
  EXPECT_EQ(clean.time_stamps.size(), 1106u);
  EXPECT_EQ(clean.landmark_count, 206u);
  const Eigen::Vector3d forward_27 = se3::rotation(clean.cam_T_imu) * Eigen::Vector3d::UnitX();
  EXPECT_GT(forward_27.z(), std::cos(10.0 * std::numbers::pi / 180.0));
  // The camera sits ahead of and above the IMU (KITTI: about 1.1 m forward, 0.7 m up).
  const Eigen::Vector3d camera_in_imu = se3::translation(se3::inverse(clean.cam_T_imu));
  EXPECT_GT(camera_in_imu.x(), 0.5);
  EXPECT_GT(camera_in_imu.z(), 0.3);
}

/// Median |uL - predicted uL| [px] over every later sighting of each landmark seen at least five
/// times, the landmark triangulated at its first sighting and the poses dead-reckoned from the
/// (noise-free) velocities: the extrinsic reading that fits the images better gives the smaller value.
double median_reprojection_error(const VisualInertialDataset& data) {
  std::vector<Eigen::Matrix4d> poses{Eigen::Matrix4d::Identity()};
  for (const auto& step : data.steps) poses.push_back(se3::normalized(poses.back() * se3::exp(step.dt * step.control)));
  StereoPixelsSe3 camera;
  camera.calibration = data.calibration;
  camera.cam_T_imu = data.cam_T_imu;
  std::map<LandmarkId, std::vector<std::pair<std::size_t, Eigen::Vector4d>>> sightings;
  for (const auto& o : data.first_observations) sightings[o.landmark_id].push_back({0, o.z});
  for (std::size_t k = 0; k < data.steps.size(); ++k)
    for (const auto& o : data.steps[k].observations) sightings[o.landmark_id].push_back({k + 1, o.z});
  std::vector<double> errors;
  for (const auto& [id, seen] : sightings) {
    if (seen.size() < 5 || seen.front().second(0) - seen.front().second(2) <= 1.0) continue;
    const Eigen::Vector3d m = camera.initialize(poses[seen.front().first], seen.front().second).m;
    for (std::size_t i = 1; i < seen.size(); ++i) {
      try {
        errors.push_back(std::abs(camera.predict(poses[seen[i].first], m).z(0) - seen[i].second(0)));
      } catch (const numerical_error&) {
        errors.push_back(1e3);  // behind the camera: as wrong as it gets
      }
    }
  }
  std::nth_element(errors.begin(), errors.begin() + static_cast<std::ptrdiff_t>(errors.size() / 2), errors.end());
  return errors[errors.size() / 2];
}

TEST(VisualInertialNpz, TheCamTImuTranslationOfThe0027FilesIsTheCameraPosition) {
  // ../shared/data/README.md: in 0027_*.npz, cam_T_imu's rotation maps IMU to camera axes but its
  // translation looks like the camera's position in the IMU frame. Checked against the images: the
  // landmarks of 0027_clean reproject better with that reading than with a proper cam_T_imu.
  const auto path = test::shared_data("ece276a/0027_clean.npz");
  SEXTANT_REQUIRE_DATA(path);
  const double as_position = median_reprojection_error(read_visual_inertial_npz(path));
  const double as_proper =
      median_reprojection_error(read_visual_inertial_npz(path, {.cam_T_imu_translation_is_camera_position = false}));
  std::printf("0027_clean median reprojection error: translation read as camera position %.2f px, as proper cam_T_imu %.2f px\n",
              as_position, as_proper);
  EXPECT_LT(as_position, as_proper);
}

TEST(VisualInertialNpz, The03ExtrinsicIsReadInTheAxesOfItsVelocities) {
  // 03.npz's imu_T_cam has the camera's x (right) along the IMU's +y and its y (down) along +z:
  // x-forward, y-right, z-down axes. Integrated in those axes its yaw rate turns the wrong way for
  // the images; re-based onto x-forward, y-left, z-up (KITTI's OXTS) the landmarks reproject better.
  const auto path = test::shared_data("ece276a/03.npz");
  SEXTANT_REQUIRE_DATA(path);
  const double rebased = median_reprojection_error(read_visual_inertial_npz(path));
  const double as_stored =
      median_reprojection_error(read_visual_inertial_npz(path, {.rebase_forward_right_down_extrinsic = false}));
  std::printf("03 median reprojection error: extrinsic re-based onto the velocities' axes %.2f px, as stored %.2f px\n",
              rebased, as_stored);
  EXPECT_LT(rebased, as_stored);
}

}  // namespace
}  // namespace sextant::io
