// Face adjacency by sorting face keys: a counting sort of the 4n faces on their smallest vertex
// (compressed rows, one bucket per vertex), then a small sort of each bucket on (middle, largest)
// vertex, and equal keys paired. No hashing; both passes are split over the cores.
#include "foxi/model/adjacency.hpp"

#include <algorithm>
#include <cassert>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>

#include "derived.hpp"
#include "foxi/model/parallel.hpp"

namespace foxi {
namespace {

// One tet face in its vertex bucket: the two larger vertices of the triangle (middle << 32 | largest,
// so that one integer comparison orders them) and the face id 4t+f. Packed to 12 bytes.
struct __attribute__((packed)) FaceEntry {
  std::uint64_t key;
  std::uint32_t face;
};
static_assert(sizeof(FaceEntry) == 12);

inline std::uint64_t face_key(std::uint32_t mid, std::uint32_t max) {
  return (std::uint64_t{mid} << 32) | max;
}
inline bool key_less(const FaceEntry& a, const FaceEntry& b) { return a.key < b.key; }
inline bool key_equal(const FaceEntry& a, const FaceEntry& b) { return a.key == b.key; }

// Sorts the 4 vertices of a tet with their positions (a 5-comparator network).
struct SortedTet {
  std::uint32_t v[4];
  std::uint8_t pos[4];
};
inline SortedTet sort_tet(const std::uint32_t* t) {
  SortedTet s{{t[0], t[1], t[2], t[3]}, {0, 1, 2, 3}};
  auto cs = [&s](int i, int j) {
    if (s.v[j] < s.v[i]) {
      std::swap(s.v[i], s.v[j]);
      std::swap(s.pos[i], s.pos[j]);
    }
  };
  cs(0, 1);
  cs(2, 3);
  cs(0, 2);
  cs(1, 3);
  cs(1, 2);
  return s;
}

// body(i) once on each of `threads` threads (thread i takes range(i)).
template <class F>
void parallel_for_threads(unsigned threads, F&& body) {
  detail::parallel_for(
      threads, threads, [&](std::size_t, std::size_t, unsigned i) { body(i); }, 0);
}

struct Counts {
  std::size_t interior = 0, boundary = 0, nonmanifold = 0;
};

}  // namespace

FaceAdjacency compute_face_adjacency(const MeshView& mesh) {
  FaceAdjacency adj;
  const std::size_t n = mesh.tet_count();
  if (n >= (std::size_t{1} << 30)) throw std::length_error("face adjacency: more than 2^30 tets");
  adj.neighbour.assign(4 * n, kNone);
  if (n == 0) return adj;
  const std::uint32_t* tet = mesh.tet.data();

  unsigned threads = 1;
  if (n >= 50000) threads = std::clamp(std::thread::hardware_concurrency(), 1u, 8u);
  auto range = [n, threads](unsigned i) {
    return std::pair<std::size_t, std::size_t>(n * i / threads, n * (i + 1) / threads);
  };

  // Bucket count: one past the largest vertex index named (robust to indices out of range).
  std::vector<std::uint32_t> tmax(threads, 0);
  parallel_for_threads(threads, [&](unsigned i) {
    auto [b, e] = range(i);
    std::uint32_t m = 0;
    for (std::size_t k = 4 * b; k < 4 * e; ++k) m = std::max(m, tet[k]);
    tmax[i] = m;
  });
  const std::size_t buckets = std::size_t{*std::max_element(tmax.begin(), tmax.end())} + 1;
  // Indices past the nodes are tolerated (validate() reports them) while the buckets stay small.
  if (buckets > std::max(mesh.node_count(), 4 * n) + 1)
    throw std::invalid_argument("face adjacency: vertex index " + std::to_string(buckets - 1) +
                                " out of range for " + std::to_string(mesh.node_count()) + " nodes");

  // Pass 1: each thread counts the faces of its tets per smallest vertex. A face's smallest vertex
  // is the tet's smallest vertex (3 faces) or its second smallest (the face opposite the smallest).
  std::vector<std::uint32_t> count(threads * buckets, 0);
  parallel_for_threads(threads, [&](unsigned i) {
    auto [b, e] = range(i);
    std::uint32_t* c = count.data() + i * buckets;
    for (std::size_t t = b; t < e; ++t) {
      SortedTet s = sort_tet(tet + 4 * t);
      c[s.v[0]] += 3;
      c[s.v[1]] += 1;
    }
  });
  // Exclusive prefix over (vertex, thread): thread i's faces of vertex v follow thread i-1's.
  std::vector<std::size_t> bucket_start(buckets + 1);
  {
    std::size_t sum = 0;
    for (std::size_t v = 0; v < buckets; ++v) {
      bucket_start[v] = sum;
      for (unsigned i = 0; i < threads; ++i) {
        std::uint32_t c = count[i * buckets + v];
        count[i * buckets + v] = static_cast<std::uint32_t>(sum - bucket_start[v]);
        sum += c;
      }
    }
    bucket_start[buckets] = sum;
    assert(sum == 4 * n);
  }

  // Pass 2: scatter the faces into their buckets.
  // Not value-initialised: every entry is written below.
  std::unique_ptr<FaceEntry[]> entries_storage(new FaceEntry[4 * n]);
  FaceEntry* const entries = entries_storage.get();
  parallel_for_threads(threads, [&](unsigned i) {
    auto [b, e] = range(i);
    std::uint32_t* c = count.data() + i * buckets;
    for (std::size_t t = b; t < e; ++t) {
      SortedTet s = sort_tet(tet + 4 * t);
      const std::uint32_t base = static_cast<std::uint32_t>(4 * t);
      // The face opposite sorted vertex k consists of the other three, still in order.
      FaceEntry* e0 = entries + bucket_start[s.v[0]] + c[s.v[0]];
      c[s.v[0]] += 3;
      e0[0] = {face_key(s.v[2], s.v[3]), base + s.pos[1]};  // opposite v1
      e0[1] = {face_key(s.v[1], s.v[3]), base + s.pos[2]};  // opposite v2
      e0[2] = {face_key(s.v[1], s.v[2]), base + s.pos[3]};  // opposite v3
      entries[bucket_start[s.v[1]] + c[s.v[1]]++] = {face_key(s.v[2], s.v[3]), base + s.pos[0]};  // opp. v0
    }
  });
  count = {};

  // Pass 3: sort each bucket on (mid, max) and pair equal keys. Threads take bucket ranges holding
  // about equal numbers of faces.
  std::vector<std::size_t> vsplit(threads + 1, buckets);
  vsplit[0] = 0;
  for (unsigned i = 1; i < threads; ++i) {
    std::size_t target = 4 * n * i / threads;
    vsplit[i] = static_cast<std::size_t>(std::lower_bound(bucket_start.begin(), bucket_start.end(), target) -
                                         bucket_start.begin());
    vsplit[i] = std::min(std::max(vsplit[i], vsplit[i - 1]), buckets);
  }
  std::vector<Counts> counts(threads);
  std::uint32_t* nb = adj.neighbour.data();
  parallel_for_threads(threads, [&](unsigned i) {
    Counts cnt;
    for (std::size_t v = vsplit[i]; v < vsplit[i + 1]; ++v) {
      FaceEntry* first = entries + bucket_start[v];
      FaceEntry* last = entries + bucket_start[v + 1];
      const std::size_t len = static_cast<std::size_t>(last - first);
      if (len == 0) continue;
      if (len <= 24) {  // insertion sort: buckets are small for bounded vertex degree
        for (FaceEntry* p = first + 1; p < last; ++p) {
          FaceEntry x = *p;
          FaceEntry* q = p;
          while (q > first && key_less(x, q[-1])) {
            *q = q[-1];
            --q;
          }
          *q = x;
        }
      } else {
        std::sort(first, last, key_less);
      }
      for (FaceEntry* p = first; p < last;) {
        FaceEntry* q = p + 1;
        while (q < last && key_equal(*p, *q)) ++q;
        const std::size_t group = static_cast<std::size_t>(q - p);
        if (group == 1) {
          ++cnt.boundary;
        } else if (group == 2) {
          nb[p[0].face] = p[1].face;
          nb[p[1].face] = p[0].face;
          ++cnt.interior;
        } else {
          ++cnt.nonmanifold;
        }
        p = q;
      }
    }
    counts[i] = cnt;
  });
  for (const Counts& c : counts) {
    adj.interior_faces += c.interior;
    adj.boundary_faces += c.boundary;
    adj.nonmanifold_faces += c.nonmanifold;
  }
  return adj;
}

const FaceAdjacency& face_adjacency(const MeshView& mesh) {
  DerivedData& d = derived_of(mesh);
  std::lock_guard<std::mutex> g(d.lock);
  if (!d.adjacency) d.adjacency = std::make_unique<FaceAdjacency>(compute_face_adjacency(mesh));
  return *d.adjacency;
}

}  // namespace foxi
