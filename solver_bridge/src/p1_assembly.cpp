#include "p1_assembly.hpp"

#include <algorithm>
#include <cstdint>
#include <numeric>

namespace foxi::detail {

NodeTets node_tets(const Mesh& mesh) {
  NodeTets nt;
  const std::size_t nn = mesh.node_count();
  nt.node_start.assign(nn + 1, 0);
  for (std::uint32_t v : mesh.tet) ++nt.node_start[v + 1];
  std::partial_sum(nt.node_start.begin(), nt.node_start.end(), nt.node_start.begin());
  nt.item.resize(mesh.tet.size());
  std::vector<std::size_t> fill(nt.node_start.begin(), nt.node_start.end() - 1);
  for (std::size_t i = 0; i < mesh.tet.size(); ++i)
    nt.item[fill[mesh.tet[i]]++] = static_cast<std::uint32_t>(i);
  return nt;
}

CsrPattern node_pattern(const Mesh& mesh, const NodeTets& nt, unsigned threads) {
  const std::size_t nn = mesh.node_count();
  threads = thread_count(threads);
  // Each thread builds the rows of its own node range; the pieces are joined afterwards.
  std::vector<std::vector<std::uint32_t>> cols(threads);
  std::vector<std::size_t> sizes(nn, 0);
  parallel_for(
      nn, threads,
      [&](std::size_t b, std::size_t e, unsigned t) {
        std::vector<std::uint32_t>& out = cols[t];
        out.reserve((e - b) * 16);
        // The row's distinct neighbours through a dense mark (last row that saw each node), then a
        // sort of those few (a tet node has about 15 of them, but 4 times as many tet corners).
        std::vector<std::size_t> seen(nn, SIZE_MAX);
        for (std::size_t v = b; v < e; ++v) {
          const std::size_t first = out.size();
          for (std::size_t k = nt.node_start[v]; k < nt.node_start[v + 1]; ++k) {
            const std::uint32_t* tv = &mesh.tet[nt.item[k] & ~3u];
            for (int c = 0; c < 4; ++c)
              if (seen[tv[c]] != v) {
                seen[tv[c]] = v;
                out.push_back(tv[c]);
              }
          }
          std::sort(out.begin() + static_cast<std::ptrdiff_t>(first), out.end());
          sizes[v] = out.size() - first;
        }
      },
      50000);
  CsrPattern p;
  p.row_start.assign(nn + 1, 0);
  for (std::size_t v = 0; v < nn; ++v) p.row_start[v + 1] = p.row_start[v] + sizes[v];
  p.col.resize(p.row_start[nn]);
  // Slices are contiguous and in thread order, so the pieces are copied one after the other.
  std::size_t at = 0;
  for (unsigned t = 0; t < threads; ++t) {
    std::copy(cols[t].begin(), cols[t].end(), p.col.begin() + static_cast<std::ptrdiff_t>(at));
    at += cols[t].size();
  }
  return p;
}

}  // namespace foxi::detail
