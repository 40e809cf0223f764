#pragma once
// A particle filter's path as a persistent list: a particle's poses from the first to the last, where
// the copies resampling makes share every pose before their own. The cloud's paths together hold
// about (steps + particles x the depth at which their ancestries meet) poses, not steps x particles
// (Jacob, Murray and Rubenthaler, "Path storage in the particle filter", Stat. Comput. 2015).
#include <algorithm>
#include <cstddef>
#include <functional>
#include <memory>
#include <span>
#include <utility>
#include <vector>

#include "sextant/core/error.hpp"

namespace sextant {

template <class Pose>
class ParticlePath {
  struct Node {
    Pose pose;
    /// mutable so that ~Node can take it over: a path of 10^5 poses would otherwise be released
    /// by 10^5 nested destructor calls.
    mutable std::shared_ptr<const Node> before;
    std::size_t size;  ///< poses from the first up to this one

    Node(Pose p, std::shared_ptr<const Node> b)
        : pose(std::move(p)), before(std::move(b)), size(before ? before->size + 1 : 1) {}
    Node(const Node&) = delete;
    Node& operator=(const Node&) = delete;
    /// Releases the poses before this one in a loop, as far as no other path shares them.
    ~Node() {
      auto next = std::move(before);
      while (next && next.use_count() == 1) next = std::move(next->before);
    }
  };

 public:
  /// One distinct pose of a set of paths at one step, with the summed weight of the paths through it.
  struct WeightedPose {
    const Pose* pose;
    double weight;
  };

  std::size_t size() const { return last_ ? last_->size : 0; }
  bool empty() const { return !last_; }
  const Pose& back() const { return last_->pose; }
  void push_back(Pose pose) { last_ = std::make_shared<const Node>(std::move(pose), last_); }
  /// The last pose replaced (a step's pose once its update has moved it), or pushed onto an empty path.
  void replace_back(Pose pose) {
    last_ = std::make_shared<const Node>(std::move(pose), last_ ? last_->before : nullptr);
  }

  /// Walks the paths back from their last pose to their first: visit(j, poses) for j = size() - 1
  /// down to 0, with the distinct poses the paths hold at step j and their summed weights (paths that
  /// share an ancestor there count once). The paths must be of one length. O(steps + the poses
  /// visited), log factor aside: once every path shares its ancestor, one pose a step.
  template <class Visit>
  static void walk_back(std::span<const ParticlePath* const> paths, std::span<const double> weights, Visit&& visit) {
    if (paths.size() != weights.size()) throw invalid_input_error("ParticlePath::walk_back: one weight per path");
    if (paths.empty()) return;
    const std::size_t length = paths.front()->size();
    std::vector<std::pair<const Node*, double>> level;
    level.reserve(paths.size());
    for (std::size_t i = 0; i < paths.size(); ++i) {
      if (paths[i]->size() != length) throw invalid_input_error("ParticlePath::walk_back: paths of different lengths");
      level.emplace_back(paths[i]->last_.get(), weights[i]);
    }
    std::vector<WeightedPose> poses;
    for (std::size_t j = length; j-- > 0;) {
      merge_shared(level);
      poses.clear();
      for (const auto& [node, weight] : level) poses.push_back({&node->pose, weight});
      visit(j, std::span<const WeightedPose>(poses));
      for (auto& entry : level) entry.first = entry.first->before.get();
    }
  }

 private:
  /// Paths through one node become one entry holding their summed weight.
  static void merge_shared(std::vector<std::pair<const Node*, double>>& level) {
    if (level.size() < 2) return;
    std::sort(level.begin(), level.end(),
              [](const auto& a, const auto& b) { return std::less<const Node*>{}(a.first, b.first); });
    std::size_t kept = 0;
    for (std::size_t i = 1; i < level.size(); ++i)
      if (level[i].first == level[kept].first)
        level[kept].second += level[i].second;
      else
        level[++kept] = level[i];
    level.resize(kept + 1);
  }

  std::shared_ptr<const Node> last_;
};

}  // namespace sextant
