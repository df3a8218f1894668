// Internal to the mesher: disjoint sets, for grouping facets and triangle sides.
#pragma once

#include <algorithm>
#include <cstdint>
#include <numeric>
#include <vector>

namespace foxi::detail {

// Disjoint sets of 0..n-1; a set's root is its smallest member.
struct UnionFind {
  std::vector<std::uint32_t> parent;
  explicit UnionFind(std::size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0u); }
  std::uint32_t find(std::uint32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  }
  void unite(std::uint32_t a, std::uint32_t b) {
    a = find(a);
    b = find(b);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  }
};

}  // namespace foxi::detail
