#pragma once
// MRPT's own EKF-SLAM (CRangeBearingKFSLAM2D, CRangeBearingKFSLAM) run over a rawlog as MRPT's
// kf-slam app runs it: the peer that tests and benchmarks compare sextant's EkfSlam with, in the same process.
#include <Eigen/Core>
#include <map>
#include <mrpt/obs/CRawlog.h>
#include <mrpt/config/CConfigFile.h>
#include <mrpt/slam/CRangeBearingKFSLAM.h>
#include <mrpt/slam/CRangeBearingKFSLAM2D.h>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "sextant/core/observation.hpp"

namespace sextant::test {

/// The (action, sensory frame) pairs of a rawlog, decoded once.
using MrptActionFramePairs = std::vector<std::pair<mrpt::obs::CActionCollection::Ptr, mrpt::obs::CSensoryFrame::Ptr>>;

inline MrptActionFramePairs read_mrpt_pairs(const std::string& path) {
  mrpt::obs::CRawlog log;
  if (!log.loadFromRawLogFile(path)) throw std::runtime_error("cannot read " + path);
  MrptActionFramePairs out;
  mrpt::obs::CActionCollection::Ptr action;
  mrpt::obs::CSensoryFrame::Ptr frame;
  // A pair needs two entries: past the last one MRPT would print an "Index out of bounds" exception.
  for (std::size_t entry = 0; entry + 1 < log.size() && log.getActionObservationPair(action, frame, entry);)
    out.emplace_back(action, frame);
  return out;
}

/// Runs CRangeBearingKFSLAM2D with the given sensor noise (MRPT's EKF-SLAM_test_2d.ini: range
/// 0.03 m, bearing 0.1 deg) over the pairs; returns its final map as (id, position).
inline std::vector<std::pair<LandmarkId, Eigen::Vector2d>> run_mrpt_kf_slam_2d(const MrptActionFramePairs& pairs,
                                                                                double std_range, double std_yaw) {
  mrpt::slam::CRangeBearingKFSLAM2D filter;
  filter.setVerbosityLevel(mrpt::system::LVL_ERROR);
  filter.options.std_sensor_range = static_cast<float>(std_range);
  filter.options.std_sensor_yaw = static_cast<float>(std_yaw);
  for (auto [action, frame] : pairs) filter.processActionObservation(action, frame);  // MRPT takes Ptr&
  mrpt::poses::CPosePDFGaussian pose;
  std::vector<mrpt::math::TPoint2D> landmarks;
  std::map<unsigned int, mrpt::maps::CLandmark::TLandmarkID> ids;
  mrpt::math::CVectorDouble full_state;
  mrpt::math::CMatrixDouble full_cov;
  filter.getCurrentState(pose, landmarks, ids, full_state, full_cov);
  std::vector<std::pair<LandmarkId, Eigen::Vector2d>> map;
  for (std::size_t i = 0; i < landmarks.size(); ++i)
    map.emplace_back(ids.at(static_cast<unsigned>(i)), Eigen::Vector2d(landmarks[i].x, landmarks[i].y));
  return map;
}

/// Runs CRangeBearingKFSLAM (6D robot, 3D landmarks) over the pairs with every option from an ini
/// file, as kf-slam runs it (e.g. EKF-SLAM_6D_test_datassoc.ini: full EKF, JCBB); returns the final
/// landmark positions.
inline std::vector<Eigen::Vector3d> run_mrpt_kf_slam_3d(const MrptActionFramePairs& pairs, const std::string& ini) {
  mrpt::slam::CRangeBearingKFSLAM filter;
  filter.loadOptions(mrpt::config::CConfigFile(ini));
  filter.setVerbosityLevel(mrpt::system::LVL_ERROR);
  for (auto [action, frame] : pairs) filter.processActionObservation(action, frame);
  mrpt::poses::CPose3DQuatPDFGaussian pose;
  std::vector<mrpt::math::TPoint3D> landmarks;
  std::map<unsigned int, mrpt::maps::CLandmark::TLandmarkID> ids;
  mrpt::math::CVectorDouble full_state;
  mrpt::math::CMatrixDouble full_cov;
  filter.getCurrentState(pose, landmarks, ids, full_state, full_cov);
  std::vector<Eigen::Vector3d> out;
  for (const auto& p : landmarks) out.emplace_back(p.x, p.y, p.z);
  return out;
}

/// Mean distance of a map's landmarks to the truth.
inline double mean_map_error(const std::map<LandmarkId, Eigen::Vector2d>& truth,
                             const std::vector<std::pair<LandmarkId, Eigen::Vector2d>>& map) {
  double sum = 0.0;
  for (const auto& [id, position] : map) sum += (position - truth.at(id)).norm();
  return map.empty() ? 0.0 : sum / static_cast<double>(map.size());
}

}  // namespace sextant::test
