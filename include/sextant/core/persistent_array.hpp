#pragma once
/// \file An array with value semantics whose copies share structure: a complete binary tree of
/// immutable nodes. Copying is O(1), reading or writing an element O(log n) (a write copies the
/// path from the root, "path copying"), so N particles can share one landmark map after
/// resampling and each pays only for the landmarks it changes (thesis §3.7.1, Fig. 13).

#include <cstddef>
#include <memory>
#include <stdexcept>
#include <utility>
#include <vector>

namespace sextant {

template <class T>
class PersistentArray {
 public:
  std::size_t size() const { return size_; }
  bool empty() const { return size_ == 0; }

  const T& operator[](std::size_t i) const {
    const Node* node = root_.get();
    for (int level = height_ - 1; level >= 0; --level) node = node->child[(i >> level) & 1u].get();
    return node->value;
  }

  /// Returns a reference to a fresh copy of element i (the path to it is copied; other copies of
  /// this array keep the old element).
  T& mutate(std::size_t i) {
    Node* node = writable(root_);
    for (int level = height_ - 1; level >= 0; --level) node = writable(node->child[(i >> level) & 1u]);
    return node->value;
  }
  void set(std::size_t i, T value) { mutate(i) = std::move(value); }

  void push_back(T value) {
    if (size_ == (std::size_t{1} << height_) || !root_) grow();
    ++size_;
    mutate(size_ - 1) = std::move(value);
  }

  /// True when both arrays share their whole tree (e.g. a copy not yet written to).
  bool shares_storage_with(const PersistentArray& other) const { return root_ == other.root_; }

 private:
  struct Node {
    std::shared_ptr<const Node> child[2];
    T value{};
  };
  using NodePtr = std::shared_ptr<const Node>;

  /// The node itself when nobody else holds it, else a fresh copy put in its place.
  static Node* writable(NodePtr& node) {
    if (!node || node.use_count() > 1) node = node ? std::make_shared<Node>(*node) : std::make_shared<Node>();
    return const_cast<Node*>(node.get());  // owned by this array alone from here on
  }

  /// Doubles the capacity: the old tree becomes the left half of a new root.
  void grow() {
    if (!root_) {
      root_ = std::make_shared<Node>();
      height_ = 0;
      return;
    }
    auto root = std::make_shared<Node>();
    root->child[0] = root_;
    root_ = std::move(root);
    ++height_;
  }

  NodePtr root_;
  std::size_t size_ = 0;
  int height_ = 0;  ///< capacity is 2^height
};

/// The naive alternative for comparison: every copy copies all elements (O(n)).
template <class T>
class CopiedArray {
 public:
  std::size_t size() const { return values_.size(); }
  const T& operator[](std::size_t i) const { return values_[i]; }
  T& mutate(std::size_t i) { return values_[i]; }
  void set(std::size_t i, T value) { values_[i] = std::move(value); }
  void push_back(T value) { values_.push_back(std::move(value)); }

 private:
  std::vector<T> values_;
};

}  // namespace sextant
