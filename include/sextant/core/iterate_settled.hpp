#pragma once
/// \file The iterated updates' one stopping rule (EkfOptions, SeifOptions and FastSlamOptions::
/// iterations: Gauss-Newton on the prior and the step's measurements, Bell and Cathey 1993).

namespace sextant {

/// An iterate has settled when it moved the estimate by at most 1e-9 of the step the update makes
/// from the prior, plus one (so that a step of zero stops too); both as infinity norms.
inline bool iterate_settled(double moved, double step) { return moved <= 1e-9 * (1.0 + step); }

}  // namespace sextant
