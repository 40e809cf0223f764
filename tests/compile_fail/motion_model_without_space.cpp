// Must NOT compile: the back-end has to name what the model lacks (checked by ctest on the output).
#include <sextant/sextant.hpp>

struct MotionWithoutSpace {
  using State = Eigen::Vector2d;
  using Control = Eigen::Vector2d;
  static constexpr int kDim = 2;
  sextant::MotionPrediction<State, 2> predict(const State&, const Control&, double) const { return {}; }
};

int main() {
  sextant::EkfSlam<MotionWithoutSpace, sextant::BeaconOffset2D> ekf{MotionWithoutSpace{}, sextant::BeaconOffset2D{}, {}};
}
