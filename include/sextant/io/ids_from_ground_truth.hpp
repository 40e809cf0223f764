#pragma once
/// \file Landmark ids for a data set that has none but has ground truth: each frame's observations
/// take the ids of distinct true landmarks that explain them jointly best from the true pose, the
/// least total (z - h(x, m))^T Q^-1 (z - h(x, m)) over the frame (a sensor sees a landmark once a
/// frame). That is the association a perfect front-end would make; it scores data association
/// and gives an oracle run to compare with.

#include <algorithm>
#include <cstddef>
#include <numeric>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "sextant/core/error.hpp"
#include "sextant/core/gaussian.hpp"
#include "sextant/core/min_cost_assignment.hpp"
#include "sextant/io/landmark_dataset.hpp"

namespace sextant::io {

/// How clear-cut the inferred ids were.
struct InferredIds {
  std::size_t observations = 0;
  double worst_nis = 0.0;  ///< largest normalized squared residual of an observation to its landmark
  /// Smallest ratio, over observations, of the second-nearest landmark's NIS to the nearest's
  /// (large: no observation was near two landmarks).
  double smallest_margin = std::numeric_limits<double>::infinity();
  /// Observations whose landmark is not the one nearest to them alone: another measurement of the
  /// same frame was nearer to that one.
  std::size_t resolved_jointly = 0;
};

namespace detail {

/// NIS of each observation of step k (rows) against each true landmark (columns, in `ids` order).
template <class Dataset>
Eigen::MatrixXd nis_to_true_landmarks(const Dataset& data, std::size_t k, const std::vector<LandmarkId>& ids) {
  const auto& observations = data.steps[k].observations;
  Eigen::MatrixXd nis(static_cast<Eigen::Index>(observations.size()), static_cast<Eigen::Index>(ids.size()));
  for (Eigen::Index j = 0; j < nis.cols(); ++j) {
    const auto predicted = data.sensor.predict(data.true_poses[k + 1], data.true_landmarks.at(ids[static_cast<std::size_t>(j)]));
    const auto noise = cholesky_or_throw(predicted.Q, "measurement noise");
    for (Eigen::Index i = 0; i < nis.rows(); ++i)
      nis(i, j) = mahalanobis_squared(noise, data.sensor.residual(observations[static_cast<std::size_t>(i)].z, predicted.z));
  }
  return nis;
}

/// The column of each row at the least total NIS, no column twice (+inf: the landmark cannot explain
/// the observation). An observation's landmark is then among its `rows` nearest (else one of those
/// would be free and nearer), so the assignment runs on those columns only.
inline std::vector<std::size_t> distinct_nearest(const Eigen::MatrixXd& nis, const std::string& where) {
  const auto rows = static_cast<std::size_t>(nis.rows()), cols = static_cast<std::size_t>(nis.cols());
  if (rows > cols)
    throw invalid_input_error(where + ": more observations than true landmarks, so some landmark was seen twice");
  std::vector<std::size_t> order(cols), kept;
  std::vector<char> keep(cols, 0);
  for (std::size_t i = 0; i < rows; ++i) {
    std::iota(order.begin(), order.end(), std::size_t{0});
    const auto by_nis = [&](std::size_t a, std::size_t b) { return nis(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(a)) < nis(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(b)); };
    std::nth_element(order.begin(), order.begin() + static_cast<std::ptrdiff_t>(rows - 1), order.end(), by_nis);
    for (std::size_t r = 0; r < rows; ++r) keep[order[r]] = 1;
  }
  for (std::size_t j = 0; j < cols; ++j)
    if (keep[j]) kept.push_back(j);
  Eigen::MatrixXd candidates(nis.rows(), static_cast<Eigen::Index>(kept.size()));
  for (std::size_t c = 0; c < kept.size(); ++c) candidates.col(static_cast<Eigen::Index>(c)) = nis.col(static_cast<Eigen::Index>(kept[c]));
  auto columns = min_cost_assignment(candidates);
  if (!columns) throw numerical_error(where + ": no distinct true landmarks explain every observation");
  for (auto& c : *columns) c = kept[c];
  return std::move(*columns);
}

}  // namespace detail

/// Gives every observation of `data` (ids LandmarkIds::absent, ground truth attached) the id of its
/// true landmark in the frame's most likely assignment and marks the ids LandmarkIds::from_ground_truth.
template <class Dataset>
InferredIds infer_ids_from_ground_truth(Dataset& data) {
  if (data.ids != LandmarkIds::absent) throw invalid_input_error(data.path + ": its observations already have ids");
  if (data.true_landmarks.empty() || data.true_poses.size() < data.steps.size() + 1)
    throw invalid_input_error(data.path + ": ids from ground truth need the true map and a pose after every step");
  std::vector<LandmarkId> ids;
  for (const auto& entry : data.true_landmarks) ids.push_back(entry.first);
  InferredIds out;
  for (std::size_t k = 0; k < data.steps.size(); ++k) {
    auto& observations = data.steps[k].observations;
    if (observations.empty()) continue;
    const Eigen::MatrixXd nis = detail::nis_to_true_landmarks(data, k, ids);
    const std::string where = data.path + ": step " + std::to_string(k);
    for (Eigen::Index i = 0; i < nis.rows(); ++i)
      if (!(nis.row(i).minCoeff() < std::numeric_limits<double>::infinity()))
        throw numerical_error(where + ": no true landmark explains an observation");
    const auto chosen = detail::distinct_nearest(nis, where);
    for (std::size_t i = 0; i < observations.size(); ++i) {
      const auto row = nis.row(static_cast<Eigen::Index>(i));
      const double own = row(static_cast<Eigen::Index>(chosen[i]));
      Eigen::Index nearest = 0;
      const double best = row.minCoeff(&nearest);
      double second = std::numeric_limits<double>::infinity();
      for (Eigen::Index j = 0; j < row.size(); ++j)
        if (j != nearest) second = std::min(second, row(j));
      observations[i].landmark_id = ids[chosen[i]];
      ++out.observations;
      out.worst_nis = std::max(out.worst_nis, own);
      if (static_cast<std::size_t>(nearest) != chosen[i] && own > best) ++out.resolved_jointly;
      if (best > 0.0) out.smallest_margin = std::min(out.smallest_margin, second / best);
    }
  }
  data.ids = LandmarkIds::from_ground_truth;
  return out;
}

}  // namespace sextant::io
