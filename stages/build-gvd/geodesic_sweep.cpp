#include "stages/build-gvd/geodesic_sweep.h"

#include <omp.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <utility>

namespace voroudf {
namespace {

// A radix heap (Ahuja, Mehlhorn, Orlin, Tarjan 1990) over the bits of non-negative doubles, whose order as
// unsigned integers is their order as numbers. Dijkstra pops keys in non-decreasing order, which is all a
// radix heap needs; each item moves down at most 64 buckets, so a pop costs O(1) amortised instead of a
// binary heap's O(log n) cache-missing sift (a third of the geodesic sweep on fandisk). Hand-written: no
// installed library (Boost.Heap, the STL) has a monotone integer-key heap.
class RadixHeap {
 public:
  bool empty() const { return size_ == 0; }
  /// \pre key >= the last popped key, key finite and >= 0
  void push(double key, int item) {
    const uint64_t bits = Bits(key);
    bucket_[Bucket(bits)].emplace_back(bits, item);
    ++size_;
  }
  /// The item of least key (any of those with that key) and its key. \pre !empty()
  std::pair<double, int> pop() {
    if (bucket_[0].empty()) {
      size_t b = 1;
      while (bucket_[b].empty()) ++b;
      uint64_t least = bucket_[b][0].first;
      for (const auto& e : bucket_[b]) least = std::min(least, e.first);
      last_ = least;
      for (const auto& e : bucket_[b]) bucket_[Bucket(e.first)].push_back(e);
      bucket_[b].clear();
    }
    const auto [bits, item] = bucket_[0].back();
    bucket_[0].pop_back();
    --size_;
    double key;
    std::memcpy(&key, &bits, sizeof key);
    return {key, item};
  }

 private:
  static uint64_t Bits(double key) {
    uint64_t bits;
    std::memcpy(&bits, &key, sizeof bits);
    return bits;
  }
  // Bucket 0: keys equal to the last popped one; bucket b: keys whose highest bit differing from it is b - 1.
  size_t Bucket(uint64_t bits) const {
    return bits == last_ ? 0 : 64 - static_cast<size_t>(__builtin_clzll(bits ^ last_));
  }
  std::array<std::vector<std::pair<uint64_t, int>>, 65> bucket_;
  uint64_t last_ = 0;
  size_t size_ = 0;
};

// The order of (distance, label) pairs: distance first, then the lower seed index.
bool Better(double d, int l, double d_old, int l_old) { return d < d_old || (d == d_old && l < l_old); }

// Dijkstra from what `heap` holds, over the edges whose far end lies in [lo, hi). A node's label can only be
// improved by a node of strictly smaller distance (an edge adds a length that is not lost to rounding:
// nodes are at least one Morton cell apart), so it is final when its distance is popped.
void Propagate(const std::vector<size_t>& offset, const std::vector<int>& adj, const std::vector<Vec3>& node,
               size_t lo, size_t hi, RadixHeap& heap, std::vector<double>& dist, std::vector<int>& label,
               Monitor& monitor) {
  constexpr uint64_t kReport = 4096;
  uint64_t popped = 0;
  while (!heap.empty()) {
    const auto [du, u] = heap.pop();
    const size_t su = static_cast<size_t>(u);
    if (du > dist[su]) continue;
    if (++popped % kReport == 0) monitor.Advance(kReport);
    const int lu = label[su];
    for (size_t a = offset[su]; a < offset[su + 1]; ++a) {
      const size_t v = static_cast<size_t>(adj[a]);
      if (v < lo || v >= hi) continue;
      const double dv = du + (node[v] - node[su]).norm();
      if (Better(dv, lu, dist[v], label[v])) {
        dist[v] = dv;
        label[v] = lu;
        heap.push(dv, static_cast<int>(v));
      }
    }
  }
}

}  // namespace

void GeodesicSweep(const std::vector<size_t>& offset, const std::vector<int>& adj, const std::vector<Vec3>& node,
                   const std::vector<int>& node_seed, size_t parts, std::vector<double>* dist_out,
                   std::vector<int>* label_out, Monitor& monitor) {
  const size_t n = node.size();
  std::vector<double>& dist = *dist_out;
  std::vector<int>& label = *label_out;
  dist.assign(n, INFINITY);
  label.assign(n, -1);
  parts = std::clamp<size_t>(parts, 1, std::max<size_t>(n, 1));
  auto range = [&](long lp) {
    const size_t p = static_cast<size_t>(lp);
    return std::pair<size_t, size_t>(n * p / parts, n * (p + 1) / parts);
  };
  Task task(monitor, "geodesic sweep", n);
  // Hand-written (over RadixHeap): no installed library runs a multi-source sweep that also records the
  // source. Each range's sweep touches only its own nodes' values, so the ranges run in parallel.
#pragma omp parallel for schedule(dynamic, 1)
  for (long lp = 0; lp < static_cast<long>(parts); ++lp) {
    const auto [lo, hi] = range(lp);
    RadixHeap heap;
    for (size_t i = lo; i < hi; ++i)
      if (node_seed[i] >= 0) {
        dist[i] = 0.0;
        label[i] = node_seed[i];
        heap.push(0.0, static_cast<int>(i));
      }
    Propagate(offset, adj, node, lo, hi, heap, dist, label, monitor);
  }
  if (parts == 1) return;
  // The edges between ranges, seen from their near end: the improvements they bring, found in parallel and
  // applied in node order (the best per node wins, so the order changes nothing).
  std::vector<std::vector<std::pair<int, std::pair<double, int>>>> found(static_cast<size_t>(omp_get_max_threads()));
#pragma omp parallel
  {
    auto& mine = found[static_cast<size_t>(omp_get_thread_num())];
#pragma omp for schedule(static)
    for (long lp = 0; lp < static_cast<long>(parts); ++lp) {
      const auto [lo, hi] = range(lp);
      for (size_t u = lo; u < hi; ++u) {
        if (label[u] < 0) continue;
        for (size_t a = offset[u]; a < offset[u + 1]; ++a) {
          const size_t v = static_cast<size_t>(adj[a]);
          if (v >= lo && v < hi) continue;
          const double dv = dist[u] + (node[v] - node[u]).norm();
          if (Better(dv, label[u], dist[v], label[v])) mine.push_back({static_cast<int>(v), {dv, label[u]}});
        }
      }
    }
  }
  std::vector<std::pair<int, std::pair<double, int>>> improve;
  for (auto& f : found) improve.insert(improve.end(), f.begin(), f.end());
  std::sort(improve.begin(), improve.end());
  RadixHeap heap;
  for (const auto& [v, value] : improve) {
    const size_t sv = static_cast<size_t>(v);
    if (!Better(value.first, value.second, dist[sv], label[sv])) continue;
    dist[sv] = value.first;
    label[sv] = value.second;
    heap.push(value.first, v);
  }
  Propagate(offset, adj, node, 0, n, heap, dist, label, monitor);
}

}  // namespace voroudf
