#pragma once
/// \file Landmark ids for a data set that has none but has ground truth: each observation takes the
/// id of the true landmark whose measurement, predicted from the true pose, is nearest in the
/// sensor's noise metric (z - h(x, m))^T Q^-1 (z - h(x, m)). That is the association a perfect
/// front-end would make; it scores data association and gives an oracle run to compare with.

#include <cstddef>
#include <limits>
#include <string>

#include "sextant/core/error.hpp"
#include "sextant/core/gaussian.hpp"
#include "sextant/io/landmark_dataset.hpp"

namespace sextant::io {

/// How clear-cut the inferred ids were.
struct InferredIds {
  std::size_t observations = 0;
  double worst_nis = 0.0;  ///< largest normalized squared residual of an observation to its landmark
  /// Smallest ratio, over observations, of the second-nearest landmark's NIS to the nearest's
  /// (large: no observation was near two landmarks).
  double smallest_margin = std::numeric_limits<double>::infinity();
};

/// Gives every observation of `data` (ids LandmarkIds::absent, ground truth attached) the id of its
/// most likely true landmark and marks the ids LandmarkIds::from_ground_truth.
template <class Dataset>
InferredIds infer_ids_from_ground_truth(Dataset& data) {
  if (data.ids != LandmarkIds::absent) throw invalid_input_error(data.path + ": its observations already have ids");
  if (data.true_landmarks.empty() || data.true_poses.size() < data.steps.size() + 1)
    throw invalid_input_error(data.path + ": ids from ground truth need the true map and a pose after every step");
  InferredIds out;
  for (std::size_t k = 0; k < data.steps.size(); ++k)
    for (auto& o : data.steps[k].observations) {
      double best = std::numeric_limits<double>::infinity(), second = best;
      LandmarkId best_id = kNoLandmarkId;
      for (const auto& [id, m] : data.true_landmarks) {
        const auto predicted = data.sensor.predict(data.true_poses[k + 1], m);
        const double nis =
            mahalanobis_squared(cholesky_or_throw(predicted.Q, "measurement noise"), data.sensor.residual(o.z, predicted.z));
        if (nis < best) second = best, best = nis, best_id = id;
        else if (nis < second) second = nis;
      }
      if (best_id == kNoLandmarkId)
        throw numerical_error(data.path + ": step " + std::to_string(k) + ": no true landmark explains an observation");
      o.landmark_id = best_id;
      ++out.observations;
      out.worst_nis = std::max(out.worst_nis, best);
      if (best > 0.0) out.smallest_margin = std::min(out.smallest_margin, second / best);
    }
  data.ids = LandmarkIds::from_ground_truth;
  return out;
}

}  // namespace sextant::io
