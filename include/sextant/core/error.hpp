#pragma once
/// \file Exceptions thrown by sextant for bad input and failed numerics.
/// Every back-end gives the strong guarantee: after a throw, its state is exactly as before the call.

#include <stdexcept>
#include <string>

namespace sextant {

/// Base of every exception sextant throws.
class error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A control, measurement, time step or option that cannot be used (NaN/Inf, dt <= 0, ...).
class invalid_input_error : public error {
 public:
  using error::error;
};

/// A landmark id that the estimator does not hold (e.g. given to remove_landmark).
class unknown_landmark_error : public error {
 public:
  using error::error;
};

/// The same landmark id appears twice within one update.
class duplicate_landmark_error : public error {
 public:
  using error::error;
};

/// A matrix that must be symmetric positive definite is not (innovation, information, ...).
class numerical_error : public error {
 public:
  using error::error;
};

/// A sensor model cannot use this observation at the current estimate: a point at or behind the
/// camera cannot be projected, a stereo pair with disparity <= 0 cannot be triangulated. Back-ends
/// skip such an observation alone and list it in UpdateResult::unusable; every other
/// numerical_error fails the whole update.
class unobservable_error : public numerical_error {
 public:
  using numerical_error::numerical_error;
};

/// A file or text record that cannot be read; the message names the source and line.
class parse_error : public error {
 public:
  using error::error;
};

}  // namespace sextant
