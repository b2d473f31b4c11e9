#pragma once
// Disjoint sets over 0..n-1 (union by smaller root, path halving): the one union-find of voroudf.
// Deterministic: a set's root is always its smallest element.
#include <algorithm>
#include <vector>

namespace voroudf {

class UnionFind {
 public:
  explicit UnionFind(size_t n) : parent_(n) {
    for (size_t i = 0; i < n; ++i) parent_[i] = static_cast<int>(i);
  }
  /// The smallest element of x's set.
  int Find(int x) {
    while (parent_[static_cast<size_t>(x)] != x) {
      parent_[static_cast<size_t>(x)] = parent_[static_cast<size_t>(parent_[static_cast<size_t>(x)])];
      x = parent_[static_cast<size_t>(x)];
    }
    return x;
  }
  /// Merges the sets of a and b; returns whether they were apart.
  bool Union(int a, int b) {
    a = Find(a), b = Find(b);
    if (a == b) return false;
    parent_[static_cast<size_t>(std::max(a, b))] = std::min(a, b);
    return true;
  }
  size_t size() const { return parent_.size(); }

 private:
  std::vector<int> parent_;
};

}  // namespace voroudf
