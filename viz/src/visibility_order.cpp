// The power visibility order: ProgressiveOrder and visibility_order / visibility_order_into. Over 900
// lines because it is one class, ProgressiveOrder::Impl, whose phases (key pass, buckets, near-tie
// resolution, cluster expansion, the worker) share its state and its hot loops; MPVO is in
// mpvo_order.cpp, the checks and the centroid baseline in order_check.cpp.
#include "foxi/viz/visibility_order.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <deque>
#include <limits>
#include <mutex>
#include <queue>
#include <utility>
#include <future>

#if defined(__SSE2__) && defined(__x86_64__)
#include <emmintrin.h>
#endif

#include "exact.hpp"
#include "foxi/model/assert.hpp"
#include "foxi/model/adjacency.hpp"
#include "huge_page_allocator.hpp"
#include "order_geometry.hpp"
#include "foxi/model/parallel.hpp"

namespace foxi {

namespace {

using namespace order_detail;

// A prefetch that the optimiser keeps. GCC deems __builtin_prefetch free of side effects, so a
// function that only prefetches is found const by its IPA pass and every call to it removed (it
// happened to prefetch_cluster and prefetch_near_ties below); a volatile asm cannot be removed.
inline void prefetch(const void* p) {
#if defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__))
  asm volatile("prefetcht0 %0" : : "m"(*static_cast<const char*>(p)));
#else
  __builtin_prefetch(p);
#endif
}

// Stores an 8-byte entry, around the cache if `stream` (a non-temporal store: no read of the line
// before it is written); store_fence() then orders such stores before the thread's later ones.
inline void store_entry(std::uint64_t* at, std::uint64_t value, bool stream) {
#if defined(__SSE2__) && defined(__x86_64__)
  if (stream) {
    _mm_stream_si64(reinterpret_cast<long long*>(at), static_cast<long long>(value));
    return;
  }
#endif
  (void)stream;
  *at = value;
}
// Writes one 64-byte line of entries at `at` (64-byte aligned) around the cache.
inline void write_line(std::uint64_t* at, const std::uint64_t* line) {
#if defined(__SSE2__) && defined(__x86_64__)
  for (int k = 0; k < 4; ++k)
    _mm_stream_si128(reinterpret_cast<__m128i*>(at) + k,
                     _mm_loadu_si128(reinterpret_cast<const __m128i*>(line) + k));
#else
  std::copy(line, line + 8, at);
#endif
}
// Orders of 2^21 entries or more are beyond the last-level cache (16 MB for the keyed
// entries, as much again for the buckets): their big buffers are written around it.
inline bool stream_entries(std::size_t m) { return m > (std::size_t(1) << 21); }
inline void store_item(std::uint32_t* at, std::uint32_t value) {
#if defined(__SSE2__) && defined(__x86_64__)
  _mm_stream_si32(reinterpret_cast<int*>(at), static_cast<int>(value));
#else
  *at = value;
#endif
}
inline void store_fence() {
#if defined(__SSE2__) && defined(__x86_64__)
  _mm_sfence();
#endif
}

std::uint32_t rep_tet(const SphereTable& t, std::uint32_t item) {
  return (item & kClusterBit) ? t.cluster_tets[t.cluster_begin[item & ~kClusterBit]] : item;
}

void exact_key(const MeshView& m, const SphereTable& table, const View& view, std::uint32_t tet,
               exact::PowerKey& key) {
  const std::uint32_t* v = m.tet.data() + 4 * std::size_t(tet);
  double w[4];
  const double* wp = nullptr;
  if (table.weighted) {
    for (int k = 0; k < 4; ++k) w[k] = m.weight[v[k]];
    wp = w;
  }
  if (table.flat[tet]) {
    // Flat tets are point spheres at their centroid: give PowerKey a degenerate tet to say so.
    key.set(node(m, v[0]), node(m, v[1]), node(m, v[2]), node(m, v[3]), nullptr, view.perspective,
            view.perspective ? view.eye : view.dir);
    return;
  }
  key.set(node(m, v[0]), node(m, v[1]), node(m, v[2]), node(m, v[3]), wp, view.perspective,
          view.perspective ? view.eye : view.dir);
}

}  // namespace

// An entry of a near-tie run: the item's key in drawing order (ascending = drawn first) minus its
// rounding radius, so that the exact key lies in [lo, lo + 2 radius].
struct Entry {
  double lo;
  float radius;
  std::uint32_t item;
  double hi() const { return lo + 2.0 * double(radius); }
};

// A sort entry: the item's quantised key q (high 32 bits) and the item (low 32 bits). q is a
// monotone function of lo, so sorting the packed integers sorts by lo up to ties of q; entries whose
// q differ by more than the view's window are in the right order (their intervals are disjoint).
using Packed = std::uint64_t;
inline std::uint32_t q_of(Packed p) { return static_cast<std::uint32_t>(p >> 32); }
inline std::uint32_t item_of(Packed p) { return static_cast<std::uint32_t>(p); }
using PackedBuffer = std::vector<Packed, HugePageAllocator<Packed>>;

// The key pass of a whole-mesh order over the table's fixed-point keys (see prepare): for items
// [b, e) the entries, the first-level histogram (and tets per bucket beyond each item's first) and
// the head entries; returns the number of head entries met. Its inputs are plain values copied
// into the loop's frame, so that none is reloaded after each store.
struct FixedPass {
  const SphereTable::FixedKey* keys = nullptr;
  const std::uint32_t* items = nullptr;
  const std::uint32_t* cluster_begin = nullptr;
  Packed* out = nullptr;
  std::uint32_t* hist = nullptr;
  std::uint32_t* tets_hist = nullptr;
  Packed* head = nullptr;
  std::size_t head_room = 0;
  std::uint32_t q_head = 0;
  int shift = 32;
  double f[3] = {0, 0, 0};  // the eye (twice, local frame) or direction, times c_unit
  double s_unit = 0, sign = -1, shift_lo = 0, q_min = 0, q_scale = 0;
};

// The q of one fixed-point key: the one evaluation that the key pass and the head's block search
// (head_from_blocks) share, so that both give an item the same q.
template <bool kPerspective>
inline std::uint32_t fixed_q(const FixedPass& p, const SphereTable::FixedKey& k) {
  const double dot = double(k.c[0]) * p.f[0] + double(k.c[1]) * p.f[1] + double(k.c[2]) * p.f[2];
  const double key = kPerspective ? double(k.s) * p.s_unit - dot : dot;
  const double x = (p.sign * key - p.shift_lo - p.q_min) * p.q_scale;
  return x > 0 ? (x < 4294967295.0 ? static_cast<std::uint32_t>(x) : 0xFFFFFFFFu) : 0u;
}

template <bool kPerspective, bool kIdentity, bool kStream, bool kClusters>
std::size_t fixed_key_pass(const FixedPass& in, std::size_t b, std::size_t e) {
  const FixedPass p = in;
  std::size_t heads = 0;
  for (std::size_t i = b; i < e; ++i) {
    const std::uint32_t q = fixed_q<kPerspective>(p, p.keys[i]);
    const std::uint32_t item = kIdentity ? static_cast<std::uint32_t>(i) : p.items[i];
    const Packed entry = (Packed(q) << 32) | item;
    store_entry(p.out + i, entry, kStream);
    ++p.hist[q >> p.shift];
    if constexpr (kClusters) {
      if (item & kClusterBit) {
        const std::uint32_t c = item & ~kClusterBit;
        p.tets_hist[q >> p.shift] += p.cluster_begin[c + 1] - p.cluster_begin[c] - 1;
      }
    }
    if (q < p.q_head) {
      if (heads < p.head_room) p.head[heads] = entry;
      ++heads;
    }
  }
  if (kStream) store_fence();
  return heads;
}

using FixedPassFn = std::size_t (*)(const FixedPass&, std::size_t, std::size_t);
template <std::size_t... kFlags>
constexpr std::array<FixedPassFn, sizeof...(kFlags)> fixed_passes(std::index_sequence<kFlags...>) {
  return {&fixed_key_pass<(kFlags & 1) != 0, (kFlags & 2) != 0, (kFlags & 4) != 0, (kFlags & 8) != 0>...};
}
// Indexed by perspective | identity << 1 | stream << 2 | clusters << 3.
constexpr std::array<FixedPassFn, 16> kFixedPasses = fixed_passes(std::make_index_sequence<16>{});

// Buffers reused from one view to the next on the same thread (no page faults, no zeroing).
struct Workspace {
  PackedBuffer keyed;    // pass 1: the items with their q, in input order (8 bytes per item)
  PackedBuffer entries;  // the bucketed entries (8 bytes per item)
  PackedBuffer head[2];  // the head buckets' entries gathered by the key pass (per part)
};
thread_local Workspace t_workspace;

struct ProgressiveOrder::Impl {
  // The lent view, kept here (a caller's MeshView may be a temporary); `mesh` points at it.
  MeshView mesh_view;
  const MeshView* mesh = nullptr;
  const SphereTable* table = nullptr;
  View view;
  bool front_to_back = false;
  std::vector<std::uint8_t> in_subset;      // per tet, only when a subset meets clusters
  PackedBuffer sorted;                      // bucketed; each bucket sorted when handed out
  std::vector<std::uint32_t> bucket_begin;  // size buckets + 1
  std::size_t next_bucket = 0;
  std::vector<std::uint32_t> batch;
  std::size_t handed = 0, total_tets = 0;
  OrderStats stats;
  // Per-thread scratch: the local MPVO of clusters, the bucket sort, the near-tie runs, tie counts.
  struct Scratch {
    std::vector<std::uint32_t> local_tets, local_indeg, local_queue;
    std::vector<std::pair<std::uint32_t, std::uint32_t>> local_edges;
    std::vector<std::uint8_t> local_done;
    std::vector<Packed> tmp;  // the second-level counting sort
    std::vector<std::uint32_t> counts;
    std::vector<Entry> run;
    // Split clusters met in a near-tie run (cluster, members in it), and one cluster's local order.
    std::vector<std::pair<std::uint32_t, std::uint32_t>> run_clusters;
    std::vector<std::uint32_t> cluster_out;
    std::size_t near_tie_runs = 0, near_tie_items = 0, cluster_cycles = 0;
    // Buckets below this one, from where this thread began, are sorted already (sorted ahead).
    std::size_t sorted_upto = 0;
  };
  Scratch scratch;
  void add_counts(Scratch& sc) {
    stats.near_tie_runs += sc.near_tie_runs;
    stats.near_tie_items += sc.near_tie_items;
    stats.cluster_cycles += sc.cluster_cycles;
    sc.near_tie_runs = sc.near_tie_items = sc.cluster_cycles = 0;
    stats.key_range = key_range_found;
  }

  bool tet_in(std::uint32_t t) const { return in_subset.empty() || in_subset[t]; }
  // Per cluster, its tets in the subset (empty when the whole mesh is ordered).
  std::vector<std::uint32_t> cluster_in;
  // The tets an item stands for in this order.
  std::uint32_t tets_of(std::uint32_t item) const {
    if (!(item & kClusterBit)) return 1;
    const std::uint32_t k = item & ~kClusterBit;
    return cluster_in.empty() ? table->cluster_begin[k + 1] - table->cluster_begin[k] : cluster_in[k];
  }

  // The view's keys in the table's local frame: key = s - c.(2 eye) (perspective) or c.dir, drawn
  // in increasing sign * key; an item's lo is sign * key - its radius.
  bool perspective = true;
  double eye2[3] = {0, 0, 0}, dir[3] = {0, 0, 0};
  double sign = -1, ka = 1, np = 0;
  float bound = 0;         // the radius of ordinary items (their q)
  float double_bound = 0;  // the same for keys recomputed in double (near ties)
  double lo_of(std::uint32_t tet, float radius) const {
    const double* c = table->c.data() + 3 * std::size_t(tet);
    const double k = perspective ? table->s[tet] - (c[0] * eye2[0] + c[1] * eye2[1] + c[2] * eye2[2])
                                 : c[0] * dir[0] + c[1] * dir[1] + c[2] * dir[2];
    return sign * k - double(radius);
  }
  float radius_of(std::uint32_t rep) const { return radius_of(rep, bound); }
  float radius_of(std::uint32_t rep, float ordinary) const {
    if (!table->wide[rep]) return ordinary;
    return std::max(
        ordinary,
        static_cast<float>((ka * double(table->key_a[rep]) + double(table->key_b[rep]) * np) * (1 + 1e-6)));
  }
  // q = floor((lo - q_min) q_scale) clamped to 32 bits: monotone in lo (NaN goes to 0).
  double q_min = 0, q_scale = 0;
  std::uint32_t quantise(double lo) const {
    const double x = (lo - q_min) * q_scale;
    return x > 0 ? (x < 4294967295.0 ? static_cast<std::uint32_t>(x) : 0xFFFFFFFFu) : 0u;
  }
  // Neighbours in q order are "joined" (possibly out of order, resolved in double and exactly) if
  // their q differ by at most q_window, or both lie in one zone: the q range of everything whose
  // interval may overlap a wide item's (merged, sorted).
  std::uint64_t q_window = 0;
  // Near ties are fetched ahead (prefetch_near_ties) when they are expected to be more than 0.1% of
  // the entries (from about 2M tets): below that the extra pass costs more than the misses.
  bool prefetch_ties = false;
  std::vector<std::pair<std::uint32_t, std::uint32_t>> zones;
  bool joined(Packed a, Packed b) const {
    const std::uint32_t qa = q_of(a), qb = q_of(b);
    if (std::uint64_t(qb) - qa <= q_window) return true;
    if (zones.empty()) return false;
    auto z = std::lower_bound(
        zones.begin(), zones.end(), qa,
        [](const std::pair<std::uint32_t, std::uint32_t>& r, std::uint32_t q) { return r.second < q; });
    return z != zones.end() && z->first <= qa && qb <= z->second;
  }
  int bucket_shift = 32;  // first-level bucket of an entry: q >> bucket_shift
  // The entries in input order (pass 1) and what the scatter of them into `sorted` needs.
  PackedBuffer keyed;
  std::vector<std::uint32_t> scatter_start[2];  // per bucket, the next slot of each part
  std::size_t scatter_split = 0;                // part 0 is keyed[0, split), part 1 the rest
  std::size_t head_buckets = 0;                 // buckets a progressive order places first
  // The entries of the head buckets, gathered by the key pass (per part) or by head_from_blocks
  // (part 0), so that a progressive order hands out its first batch without waiting for the
  // scatter; head_fits is false if there were more than the room kept for them.
  PackedBuffer head[2];
  std::size_t head_count[2] = {0, 0};
  bool head_fits = false;
  std::size_t scatter_from = 0;  // the first bucket the worker's scatter places
  bool scattered = false;
  double key_range_found = 0;  // set by the scatter, published by add_counts
  void scatter(std::size_t from, std::size_t to);

  // The progressive path sorts ahead on a pooled thread (handed the work by the first next()), so
  // that the caller can draw one batch while the next buckets are being sorted.
  std::future<void> worker;  // valid while the sorting ahead runs or has not been waited for
  std::mutex mu;
  std::condition_variable cv;
  std::deque<std::vector<std::uint32_t>> ready;
  bool worker_done = false;
  std::atomic<bool> stop{false};
  void run_worker();
  // The first batch of a progressive order: the head buckets (gathered by the key pass) put in
  // place, sorted and emitted into `batch` on the caller's thread, unless a run of joined entries
  // may cross their end (then batch stays empty and the worker starts from bucket 0).
  void hand_out_head();

  ~Impl() {
    if (worker.valid()) {
      stop = true;
      worker.wait();
    }
    // Hand the big buffer back for the next view on this thread. (A buffer the worker thread made
    // is the same memory; the thread_local slot is this thread's.)
    if (sorted.capacity() > t_workspace.entries.capacity()) t_workspace.entries.swap(sorted);
    if (keyed.capacity() > t_workspace.keyed.capacity()) t_workspace.keyed.swap(keyed);
    for (int part = 0; part < 2; ++part)
      if (head[part].capacity() > t_workspace.head[part].capacity()) t_workspace.head[part].swap(head[part]);
  }
  // Lays out the order (sample, quantisation, buckets) and computes the keys, except for a
  // whole-mesh progressive order, which finds only its head now (head_from_blocks) and leaves the
  // other keys to its worker (deferred_key_pass).
  void prepare(std::span<const std::uint32_t> subset, bool progressive);
  std::size_t item_count = 0;      // sort items, wide ones included
  std::size_t ordinary_count = 0;  // the items that are not wide (first in keyed)
  std::uint32_t q_head = 0;        // the head's entries have q below this (0: no head)
  std::size_t head_room = 0;       // room for head entries per part
  std::vector<std::uint32_t> hist[2],
      thist[2];          // per part: entries per bucket, tets beyond each item's first
  FixedPass fixed_pass;  // the key pass over fixed-point keys (fixed_run)
  FixedPassFn fixed_run = nullptr;
  bool keys_deferred = false;  // keys left to the worker (head_from_blocks)
  std::size_t head_total = 0;  // the head's entries found by head_from_blocks
  void place_buckets(std::size_t split, bool gather);
  void head_from_blocks();
  bool deferred_key_pass();
  // Sorts one first-level bucket [begin, end) by packed value.
  // With prefetch_ties, also prefetches the keys of the near ties it finds (prefetch_near_ties).
  void sort_bucket(std::size_t begin, std::size_t end, Scratch& sc);
  template <bool kFetch>
  void sort_bucket_of(std::size_t begin, std::size_t end, Scratch& sc);
  // Calls put(item) for the items of [begin, end) in order, after putting each maximal run of joined
  // neighbours in exact order (resolve_run).
  template <class Put>
  void scan_runs(std::size_t begin, std::size_t end, Scratch& sc, Put put) {
    const Packed* a = sorted.data();
    const std::uint64_t w = q_window;
    const bool plain = zones.empty();
    for (std::size_t i = begin; i < end; ++i) {
      // Fast path: neighbours far apart in q (almost all of them).
      if (i + 1 < end && (plain ? std::uint64_t(q_of(a[i + 1])) - q_of(a[i]) <= w : joined(a[i], a[i + 1]))) {
        std::size_t j = i + 1;
        while (j + 1 < end && joined(a[j], a[j + 1])) ++j;
        resolve_run(i, j + 1, sc);
        for (; i < j; ++i) put(item_of(a[i]));
      }
      put(item_of(a[i]));
    }
  }
  void resolve_run(std::size_t begin, std::size_t end, Scratch& sc);
  // scan_runs for the common case, items that are tets and no zones, as a loop of its own that keeps
  // its output pointer in a register (through a lambda's reference it was stored at every item):
  // writes the items of [begin, end) from o on (around the cache if kStream), returns the end.
  template <bool kStream>
  std::uint32_t* emit_tets(std::size_t begin, std::size_t end, std::uint32_t* o, Scratch& sc);
  bool t_cluster_free = false;  // no item is a cluster: copy items straight out
  // A whole-mesh order of a table with clusters_split: every item is a tet (t_cluster_free), and
  // resolve_run draws each cluster whose tets meet in its run as one unit.
  bool split_clusters = false;
  // Prefetches where a cluster item's faces and tets are listed (nothing for a tet).
  void prefetch_offsets(std::uint32_t item) const {
    if (!(item & kClusterBit)) return;
    const std::uint32_t k = item & ~kClusterBit;
    prefetch(table->cluster_face_begin.data() + k);
    prefetch(table->cluster_begin.data() + k);
  }
  // Prefetches a cluster item's faces and tets ahead of its expansion (nothing for a tet).
  bool many_clusters = false;  // clusters are a sizeable part of the items
  void prefetch_cluster(std::uint32_t item) const {
    if (!(item & kClusterBit)) return;
    const SphereTable& t = *table;
    const std::uint32_t k = item & ~kClusterBit;
    const std::uint32_t f = t.cluster_face_begin[k], fe = t.cluster_face_begin[k + 1];
    prefetch(t.cluster_tets.data() + t.cluster_begin[k]);
    if (f == fe) return;
    const char* faces = reinterpret_cast<const char*>(t.face_test.data() + f);
    const char* faces_end = reinterpret_cast<const char*>(t.face_test.data() + fe);
    for (const char* p = faces; p < faces_end && p < faces + 512; p += 64) prefetch(p);
  }
  // Prefetches the double keys of the tets in near-tie pairs of [begin, end) (sorted), which
  // resolve_run reads: they lie at random places, and fetched one run after another each is a
  // cache miss waited for (a few thousand a view at 1M tets, tens of thousands at 4M).
  // (sort_bucket does it as it sorts; this pass is for the few buckets it sorts otherwise.)
  void prefetch_near_ties(std::size_t begin, std::size_t end) const {
    const Packed* a = sorted.data();
    for (std::size_t i = begin; i + 1 < end; ++i) prefetch_if_tie(a[i], a[i + 1]);
  }
  // The same for one pair of neighbours (a before b in q order).
  void prefetch_if_tie(Packed a, Packed b) const {
    if (std::uint64_t(q_of(b)) - q_of(a) > q_window) return;
    for (std::uint32_t item : {item_of(a), item_of(b)}) {
      if (item & kClusterBit) continue;  // found through the cluster tables first
      prefetch(table->c.data() + 3 * std::size_t(item));
      prefetch(table->c.data() + 3 * std::size_t(item) + 2);
      prefetch(table->s.data() + item);
      prefetch(table->wide.data() + item);
      if (split_clusters) prefetch(table->cluster_of.data() + item);
    }
  }
  // Writes the tets of one item at o (advancing it): a tet, or a cluster in its local MPVO order.
  void expand(std::uint32_t item, std::uint32_t*& o, Scratch& sc);
  // Hands out buckets [first, last) (sorting, tie fix-up, cluster expansion), appended to out, or if
  // `direct` is given, written at their places in the whole order (direct + tet_begin[bucket]);
  // returns the next bucket not consumed: a run of joined entries may take in buckets from `last`
  // up to `limit`.
  std::size_t emit_buckets(std::size_t first, std::size_t last, std::size_t limit,
                           std::vector<std::uint32_t>& out, Scratch& sc, std::uint32_t* direct = nullptr);
  // Per first-level bucket, the number of tets before it in the order (size buckets + 1): the
  // same as bucket_begin when no item is a cluster.
  std::vector<std::uint32_t> tet_begin;
};

void ProgressiveOrder::Impl::prepare(std::span<const std::uint32_t> subset, bool progressive) {
  const SphereTable& t = *table;
  const std::size_t n = t.tet_count();
  // The items: all of the mesh (precomputed), or the subset's tets and clusters.
  std::vector<std::uint32_t> own_items, own_reps, own_wide;
  std::vector<float> own_wide_a, own_wide_b;
  std::span<const std::uint32_t> items, reps, wide_items;
  std::span<const float> wide_a, wide_b;
  if (subset.empty()) {
    items = t.all_items;
    reps = t.all_rep;
    wide_items = t.wide_items;
    wide_a = t.wide_a;
    wide_b = t.wide_b;
    total_tets = n;
  } else {
    if (t.cluster_count() > 0) in_subset.assign(n, 0);
    cluster_in.assign(t.cluster_count(), 0);
    own_items.reserve(subset.size());
    for (std::uint32_t tet : subset) {
      if (!in_subset.empty()) in_subset[tet] = 1;
      std::uint32_t k = t.cluster_of.empty() ? kNone : t.cluster_of[tet];
      std::uint32_t item = tet, rep = tet;
      if (k != kNone) {
        if (cluster_in[k]++ > 0) continue;
        item = k | kClusterBit;
        rep = t.cluster_tets[t.cluster_begin[k]];
      }
      if (t.wide[rep]) {
        own_wide.push_back(item);
        own_wide_a.push_back(t.key_a[rep]);
        own_wide_b.push_back(t.key_b[rep]);
      } else {
        own_items.push_back(item);
        own_reps.push_back(rep);
      }
    }
    items = own_items;
    reps = own_reps;
    wide_items = own_wide;
    wide_a = own_wide_a;
    wide_b = own_wide_b;
    total_tets = subset.size();
  }
  const std::size_t m_main = items.size(), m = m_main + wide_items.size();
  item_count = m;
  ordinary_count = m_main;
  split_clusters = subset.empty() && t.clusters_split && t.cluster_count() > 0;
  t_cluster_free = t.cluster_count() == 0 || split_clusters;
  many_clusters = t.cluster_count() * 16 > t.all_items.size();
  stats.items = m;
  stats.wide_items = wide_items.size();
  if (m == 0) {
    bucket_begin.assign(1, 0);
    tet_begin.assign(1, 0);
    return;
  }

  // Rounding bounds: |key error| <= a + b |p|_1 (orthographic: b |d|_1), in the local frame.
  perspective = view.perspective;
  for (int k = 0; k < 3; ++k) {
    eye2[k] = 2 * (view.eye[k] - t.origin[k]);
    dir[k] = view.dir[k];
  }
  np = perspective ? 0.5 * (std::abs(eye2[0]) + std::abs(eye2[1]) + std::abs(eye2[2]))
                   : std::abs(dir[0]) + std::abs(dir[1]) + std::abs(dir[2]);
  ka = perspective ? 1.0 : 0.0;
  sign = front_to_back ? 1.0 : -1.0;  // back to front: decreasing key first
  // A whole-mesh order reads the fixed-point keys (their rounding widens the bound a little).
  const bool fixed = subset.empty() && !t.fixed_keys.empty() && t.fixed_keys.size() == m_main;
  const double bound_a = t.bound_a + (fixed ? t.fixed_a : 0.0),
               bound_b = t.bound_b + (fixed ? t.fixed_b : 0.0);
  // Rounded up to float, and a little more for the subtraction that places lo.
  bound = static_cast<float>((ka * bound_a + bound_b * np) * (1 + 1e-6));
  double_bound = static_cast<float>((ka * t.bound_a + t.bound_b * np) * (1 + 1e-6));
  stats.key_bound = bound;

  // 1. The quantisation of lo to 32 bits, over the bulk of a sample of the keys ([0.1%, 99.9%]
  // quantiles widened by an eighth each side): keys outside (far-flung spheres of slivers at the
  // hull) are clamped to the end values and sorted in double as runs of ties.
  auto item_lo = [&](std::size_t i) {
    if (i < m_main) return lo_of(reps[i], bound);
    const std::uint32_t rep = rep_tet(t, wide_items[i - m_main]);
    return lo_of(rep, radius_of(rep));
  };
  double head_lo = 0;
  {
    const std::size_t samples = std::min<std::size_t>(m, 2048);
    std::vector<double> sample(samples);
    for (std::size_t k = 0; k < samples; ++k) sample[k] = item_lo(k * m / samples);
    // Only the few smallest and the 3 largest are read: selections, not a sort (on the path to the
    // first batch).
    if (samples < 64) {
      std::sort(sample.begin(), sample.end());
    } else {
      const auto low_end = sample.begin() + std::max<std::ptrdiff_t>(std::ptrdiff_t(samples / 512), 2) + 1;
      std::nth_element(sample.begin(), low_end - 1, sample.end());
      std::sort(sample.begin(), low_end);
      std::nth_element(low_end, sample.end() - 3, sample.end());
      std::sort(sample.end() - 3, sample.end());
    }
    double kmin = sample.front(), kmax = sample.back();
    head_lo = sample[samples / 512];
    if (samples < m) {
      const double qlo = sample[2], qhi = sample[samples - 3], widen = (qhi - qlo) / 8;
      kmin = qlo - widen;
      kmax = qhi + widen;
    }
    q_min = kmin;
    q_scale = kmax > kmin ? 4294967296.0 / (kmax - kmin) : 0.0;
    // Joined neighbours: q apart by at most 2 radius q_scale plus the rounding of the map and floor.
    const double w = 2.0 * double(bound) * q_scale * (1 + 1e-9) + 2;
    q_window = w < 8e9 ? static_cast<std::uint64_t>(w) : std::uint64_t(1) << 33;
    prefetch_ties = double(q_window) * double(m) > 0.001 * 4294967296.0;
  }

  // 2. Keys, q and the first-level histogram in one pass (both cores). About 1000 entries a bucket:
  // few enough buckets that the scatter's write fronts stay in cache, and each bucket sorted when
  // handed out (sort_bucket) stays in L1/L2 (measured against 256 to 2048 a bucket).
  // Beyond the cache, at most 4096 buckets: each thread's write-combining lines (64 bytes a
  // bucket) must stay in its L2.
  const int max_bits = stream_entries(m) ? 12 : 16;
  int bits = 4;
  while (bits < max_bits && (std::size_t(1024) << bits) < m) ++bits;
  const std::size_t nb = std::size_t(1) << bits;
  const int shift = 32 - bits;
  bucket_shift = shift;
  stats.buckets = nb;
  keyed.swap(t_workspace.keyed);
  if (keyed.size() < m) keyed.resize(m);
  sorted.swap(t_workspace.entries);
  if (sorted.size() < m) sorted.resize(m);
  // The head (progressive orders only): the buckets up to the one of the sample's 0.2% quantile,
  // gathered before the scatter so that they are handed out first. Room for a few times what the
  // sample predicts; more means a skewed sample, and the head is then placed by the scatter.
  head_buckets = progressive && m >= 50000
                     ? std::min<std::size_t>((std::size_t(quantise(head_lo)) >> shift) + 1, nb)
                     : 0;
  q_head = head_buckets == 0 || head_buckets >= nb ? 0u : static_cast<std::uint32_t>(head_buckets << shift);
  head_room = q_head == 0 ? 0 : m / 128 + 8192;
  for (int part = 0; part < 2; ++part) {
    head[part].swap(t_workspace.head[part]);
    if (head[part].size() < head_room) head[part].resize(head_room);
  }
  for (int part = 0; part < 2; ++part) {
    hist[part].assign(nb, 0);
    // With clusters, the tets per bucket too (an item stands for one or more tets: counted here are
    // the tets beyond the first), so that every bucket's tets can be written at their final places.
    if (!t_cluster_free) thist[part].assign(nb, 0);
  }
  bucket_begin.assign(nb + 1, 0);
  if (!t_cluster_free) tet_begin.assign(nb + 1, 0);
  Packed* keyed_p = keyed.data();

  // The wide items (few) come after the others in keyed, and each makes a zone of joined q values.
  zones.clear();
  for (std::size_t i = m_main; i < m; ++i) {
    const std::uint32_t rep = rep_tet(t, wide_items[i - m_main]);
    const float r = radius_of(rep);
    const double lo = lo_of(rep, r);
    keyed_p[i] = (Packed(quantise(lo)) << 32) | wide_items[i - m_main];
    // Whatever overlaps [lo, lo + 2r] has its lo in [lo - 2 bound, lo + 2r] (ordinary items), or
    // its own zone meets this one (wide items).
    const std::uint64_t za = quantise(lo - 2.0 * double(bound)), zb = quantise(lo + 2.0 * double(r));
    zones.emplace_back(static_cast<std::uint32_t>(za > q_window ? za - q_window : 0),
                       static_cast<std::uint32_t>(std::min<std::uint64_t>(zb + q_window, 0xFFFFFFFFu)));
  }
  if (!zones.empty()) {
    std::sort(zones.begin(), zones.end());
    std::size_t k = 0;
    for (std::size_t z = 1; z < zones.size(); ++z) {
      if (zones[z].first <= zones[k].second)
        zones[k].second = std::max(zones[k].second, zones[z].second);
      else
        zones[++k] = zones[z];
    }
    zones.resize(k + 1);
  }

  // Tight loops over the ordinary items, on locals (the stores to the histogram could alias anything
  // reached through a reference).
  const std::uint32_t* item_p = t_cluster_free ? reps.data() : items.data();  // items are their reps then
  const std::uint32_t* cl_tets = t.cluster_tets.data();
  const std::uint32_t* cl_begin = t.cluster_begin.data();
  const double* C = t.c.data();
  const double* S = t.s.data();
  const double p0 = perspective ? eye2[0] : dir[0], p1 = perspective ? eye2[1] : dir[1],
               p2 = perspective ? eye2[2] : dir[2];
  const double shift_lo = double(bound), sgn = sign, qmin = q_min, qscale = q_scale;
  const bool persp_view = perspective;
  // Beyond the last-level cache the entries are written around it: they are read next by the
  // scatter, from memory either way, and a plain store would first read each line it writes.
  const bool stream = stream_entries(m);
  const std::uint32_t q_head_v = q_head;
  const std::size_t head_room_v = head_room;
  auto key_pass_of = [=, this](auto with_tets) {
    return [=, this](std::size_t b, std::size_t e, int part) {
      std::uint32_t* hp = hist[part].data();
      std::uint32_t* thp = thist[part].data();
      Packed* head_p = head[part].data();
      std::size_t heads = 0;
      // An item's tet: the item itself, or a cluster's first tet (reps[i], read from the cluster
      // tables instead, which saves a stream of 4 bytes per item when few items are clusters).
      auto rep_at = [=](std::size_t i) -> std::size_t {
        if constexpr (decltype(with_tets)::value) {
          const std::uint32_t item = item_p[i];
          return (item & kClusterBit) ? cl_tets[cl_begin[item & ~kClusterBit]] : item;
        } else {
          return item_p[i];
        }
      };
      auto put = [=, this, &heads](std::size_t i, double lo, std::uint32_t item) {
        const double x = (lo - qmin) * qscale;
        const std::uint32_t q = x > 0 ? (x < 4294967295.0 ? static_cast<std::uint32_t>(x) : 0xFFFFFFFFu) : 0u;
        const Packed p = (Packed(q) << 32) | item;
        store_entry(keyed_p + i, p, stream);
        ++hp[q >> shift];
        if constexpr (decltype(with_tets)::value)
          if (item_p[i] & kClusterBit) thp[q >> shift] += tets_of(item_p[i]) - 1;
        if (q < q_head_v) {
          if (heads < head_room_v) head_p[heads] = p;
          ++heads;
        }
      };
      if (persp_view) {
        for (std::size_t i = b; i < e; ++i) {
          const std::size_t tet = rep_at(i);
          const double* c = C + 3 * tet;
          put(i, sgn * (S[tet] - (c[0] * p0 + c[1] * p1 + c[2] * p2)) - shift_lo, item_p[i]);
        }
      } else {
        for (std::size_t i = b; i < e; ++i) {
          const double* c = C + 3 * rep_at(i);
          put(i, sgn * (c[0] * p0 + c[1] * p1 + c[2] * p2) - shift_lo, item_p[i]);
        }
      }
      head_count[part] = heads;
      if (stream) store_fence();
    };
  };
  head_count[0] = head_count[1] = 0;
  if (fixed) {
    FixedPass& pass = fixed_pass;
    pass = FixedPass{};
    pass.keys = t.fixed_keys.data();
    pass.items = items.data();
    pass.out = keyed_p;
    pass.cluster_begin = t.cluster_begin.data();
    pass.head_room = head_room;
    pass.q_head = q_head;
    pass.shift = shift;
    pass.f[0] = p0 * t.c_unit;
    pass.f[1] = p1 * t.c_unit;
    pass.f[2] = p2 * t.c_unit;
    pass.s_unit = t.s_unit;
    pass.sign = sign;
    pass.shift_lo = double(bound);
    pass.q_min = q_min;
    pass.q_scale = q_scale;
    // No clusters and no wide items: all_items lists every tet in order (item i is tet i).
    const bool identity = t_cluster_free && m_main == n;
    fixed_run = kFixedPasses[(perspective ? 1 : 0) | (identity ? 2 : 0) | (stream ? 4 : 0) |
                             (t_cluster_free ? 0 : 8)];
    if (q_head > 0 && t.key_order.size() == m_main) {
      // A progressive order: its head now, from the blocks that may hold it; every key later, by the
      // worker, while the caller draws the first batch.
      head_from_blocks();
      return;
    }
    const FixedPassFn run = fixed_run;
    parallel_for(m_main, [&](std::size_t b, std::size_t e, int part) {
      FixedPass own = pass;
      own.hist = hist[part].data();
      own.tets_hist = thist[part].data();
      own.head = head[part].data();
      head_count[part] = run(own, b, e);
    });
  } else if (t_cluster_free) {
    parallel_for(m_main, key_pass_of(std::false_type{}));
  } else {
    parallel_for(m_main, key_pass_of(std::true_type{}));
  }
  // The wide items go with the second part (as parallel_for splits).
  place_buckets(m_main < 50000 ? m : m_main / 2, true);
}

// Counts the wide items (and gathers those of the head if `gather`) with part 1 (part 0 if the
// key pass had one part: split == m), then places the buckets: bucket_begin, tet_begin, and where
// each part's entries of each bucket go.
void ProgressiveOrder::Impl::place_buckets(std::size_t split, bool gather) {
  const std::size_t m = item_count, nb = hist[0].size();
  const int shift = bucket_shift;
  const int wide_part = split == m ? 0 : 1;
  for (std::size_t i = ordinary_count; i < m; ++i) {
    const Packed p = keyed[i];
    const std::uint32_t q = q_of(p);
    FOXI_ASSERT((q >> shift) < nb, "bucket " << (q >> shift) << " of " << nb);
    ++hist[wide_part][q >> shift];
    if (gather && q < q_head) {
      if (head_count[wide_part] < head_room) head[wide_part][head_count[wide_part]] = p;
      ++head_count[wide_part];
    }
    if (!t_cluster_free) thist[wide_part][q >> shift] += tets_of(item_of(p)) - 1;
  }
  // Filled in place: a worker placing the buckets after the head was handed out writes the same
  // values there.
  scatter_start[0].resize(nb);
  scatter_start[1].resize(nb);
  std::uint32_t acc = 0, tets = 0;
  for (std::size_t b = 0; b < nb; ++b) {
    bucket_begin[b] = acc;
    scatter_start[0][b] = acc;
    acc += hist[0][b];
    scatter_start[1][b] = acc;
    acc += hist[1][b];
    if (!t_cluster_free) {
      tet_begin[b] = tets;
      tets += hist[0][b] + hist[1][b] + thist[0][b] + thist[1][b];
    }
  }
  bucket_begin[nb] = acc;
  FOXI_ASSERT(acc == m, "the buckets hold " << acc << " of " << m << " entries");
  if (!t_cluster_free) tet_begin[nb] = tets;
  scatter_split = split;
  if (gather) head_fits = q_head > 0 && head_count[0] <= head_room && head_count[1] <= head_room;
}

// The head of a progressive order from the key blocks (see SphereTable::KeyBlock): a block is read
// only if the least q its box allows is in the head; every entry of the head is then found (and no
// other), with the q the key pass would give it. Places the head buckets; the key pass of the
// whole mesh is left to the worker (keys_deferred).
void ProgressiveOrder::Impl::head_from_blocks() {
  const SphereTable& t = *table;
  const FixedPass& p = fixed_pass;
  const std::size_t block = SphereTable::kKeyBlock, m_keys = ordinary_count;
  const std::uint32_t* order = t.key_order.data();
  const double qh = double(q_head);
  Packed* out = head[0].data();
  std::size_t count = 0, read = 0;
  auto gather = [&](auto persp) {
    constexpr bool kPerspective = decltype(persp)::value;
    for (std::size_t k = 0; k < t.key_blocks.size(); ++k) {
      const SphereTable::KeyBlock& box = t.key_blocks[k];
      // The exact key's range over the box, widened by the rounding of the key pass and of this
      // bound (each a few ulps of the largest term: 16 is ample).
      double lo = 0, hi = 0, mag = 0;
      for (int j = 0; j < 3; ++j) {
        const double a = double(box.c_lo[j]) * p.f[j], b = double(box.c_hi[j]) * p.f[j];
        lo += std::min(a, b);
        hi += std::max(a, b);
        mag += std::max(std::abs(a), std::abs(b));
      }
      if (kPerspective) {
        const double s_lo = double(box.s_lo) * p.s_unit, s_hi = double(box.s_hi) * p.s_unit;
        const double dot_lo = lo;
        lo = s_lo - hi;
        hi = s_hi - dot_lo;
        mag += std::max(std::abs(s_lo), std::abs(s_hi));
      }
      const double least = (p.sign > 0 ? lo : -hi) - 16 * kEps * mag;
      // x is monotone in the key as evaluated (each rounding is), so no entry of the block has a q
      // below that of `least`. (A NaN bound reads the block.)
      const double x = (least - p.shift_lo - p.q_min) * p.q_scale;
      if (x >= qh) continue;
      const std::size_t e = std::min(m_keys, (k + 1) * block);
      read += e - k * block;
      // The block's keys lie at scattered places: all their misses at once.
      for (std::size_t j = k * block; j < e; ++j) {
        prefetch(p.keys + order[j]);
        prefetch(p.items + order[j]);
      }
      for (std::size_t j = k * block; j < e; ++j) {
        const std::uint32_t i = order[j];
        const std::uint32_t q = fixed_q<kPerspective>(p, p.keys[i]);
        if (q >= q_head) continue;
        if (count < head_room) out[count] = (Packed(q) << 32) | p.items[i];
        ++count;
      }
    }
  };
  if (perspective)
    gather(std::true_type{});
  else
    gather(std::false_type{});
  for (std::size_t i = ordinary_count; i < item_count; ++i)
    if (q_of(keyed[i]) < q_head) {
      if (count < head_room) out[count] = keyed[i];
      ++count;
    }
  stats.first_batch_keys = read;
  head_count[0] = count;
  head_count[1] = 0;
  head_total = count;
  head_fits = count <= head_room;
  keys_deferred = true;
  if (!head_fits) return;  // the worker places everything
  // The head buckets' places (the same as the whole histogram gives them).
  const int shift = bucket_shift;
  for (std::size_t i = 0; i < count; ++i) {
    ++bucket_begin[(q_of(out[i]) >> shift) + 1];
    if (!t_cluster_free) tet_begin[(q_of(out[i]) >> shift) + 1] += tets_of(item_of(out[i]));
  }
  for (std::size_t b = 1; b <= head_buckets; ++b) {
    bucket_begin[b] += bucket_begin[b - 1];
    if (!t_cluster_free) tet_begin[b] += tet_begin[b - 1];
  }
}

// The worker's key pass after a head found by head_from_blocks: one core (the caller draws on the
// other), in chunks between looks at the stop flag. False if stopped.
bool ProgressiveOrder::Impl::deferred_key_pass() {
  FixedPass own = fixed_pass;
  own.hist = hist[0].data();
  own.tets_hist = thist[0].data();
  own.head = nullptr;
  own.head_room = 0;
  own.q_head = 0;  // gathers nothing
  constexpr std::size_t kChunk = 1 << 16;
  for (std::size_t c = 0; c < ordinary_count; c += kChunk) {
    if (stop.load(std::memory_order_relaxed)) return false;
    fixed_run(own, c, std::min(ordinary_count, c + kChunk));
  }
  place_buckets(item_count, false);
  keys_deferred = false;
  // The blocks' bounds are proved to miss no entry of the head; the count checks it.
  if (bucket_begin[head_buckets] != head_total)
    throw std::logic_error("visibility order: the key blocks missed entries of the first batch");
  return true;
}

// Places the entries of buckets [from, to) of keyed into sorted (both cores), each part into its
// own slots of every bucket: the same layout whatever ranges the buckets are placed in. Gives up
// early (leaving the placement unfinished) when the order is stopped.
void ProgressiveOrder::Impl::scatter(std::size_t from, std::size_t to) {
  const std::size_t m = bucket_begin.back(), nb = bucket_begin.size() - 1;
  const Packed* keyed_p = keyed.data();
  Packed* out = sorted.data();
  const int shift = bucket_shift;
  auto run = [=, this](std::size_t b, std::size_t e, std::uint32_t* ps) {
    constexpr std::size_t kChunk = 1 << 16;  // entries between looks at the stop flag
    for (std::size_t c = b; c < e && !stop.load(std::memory_order_relaxed); c += kChunk) {
      const std::size_t ce = std::min(e, c + kChunk);
      if (from == 0 && to == nb) {
        for (std::size_t i = c; i < ce; ++i) {
          const Packed p = keyed_p[i];
          out[ps[q_of(p) >> shift]++] = p;
        }
      } else {
        for (std::size_t i = c; i < ce; ++i) {
          const Packed p = keyed_p[i];
          const std::size_t k = q_of(p) >> shift;
          if (k >= from && k < to) out[ps[k]++] = p;
        }
      }
    }
  };
  // Beyond the last-level cache, the whole scatter writes through per-thread line buffers
  // (software write-combining): each bucket's line is filled in a buffer that stays in L2 and a full
  // line goes to memory in one non-temporal write, with no read of the destination line first.
  // (Full lines need the buffer 64-byte aligned, which the huge-page allocator gives such sizes.)
  const bool combine =
      from == 0 && to == nb && stream_entries(m) && reinterpret_cast<std::uintptr_t>(out) % 64 == 0;
  auto run_combined = [=, this](std::size_t b, std::size_t e, std::uint32_t* ps) {
    thread_local std::vector<Packed> t_lines;
    thread_local std::vector<std::uint32_t> t_first;
    if (t_lines.size() < 8 * nb) t_lines.resize(8 * nb);
    t_first.assign(ps, ps + nb);
    Packed* lines = t_lines.data();
    const std::uint32_t* first = t_first.data();
    for (std::size_t i = b; i < e; ++i) {
      // Gives up (unfinished) when the order is stopped, as run() does.
      if ((i & 0xFFFF) == 0 && stop.load(std::memory_order_relaxed)) {
        store_fence();
        return;
      }
      const Packed p = keyed_p[i];
      const std::size_t k = q_of(p) >> shift;
      const std::uint32_t pos = ps[k]++;
      Packed* line = lines + 8 * k;
      line[pos & 7] = p;
      if ((pos & 7) != 7) continue;
      // The line [pos - 7, pos] is complete; its first slots may belong to the bucket (or part)
      // before, when it is this part's first line of bucket k: then only its own slots are stored.
      if (pos - 7 >= first[k])
        write_line(out + (pos - 7), line);
      else
        for (std::uint32_t slot = first[k]; slot <= pos; ++slot) out[slot] = line[slot & 7];
    }
    for (std::size_t k = 0; k < nb; ++k) {  // the partial last lines
      const std::uint32_t end = ps[k];
      if ((end & 7) == 0 || end == first[k]) continue;
      for (std::uint32_t slot = std::max(end & ~7u, first[k]); slot < end; ++slot)
        out[slot] = lines[8 * k + (slot & 7)];
    }
    store_fence();
  };
  const std::size_t split = scatter_split;
  if (split == m) {
    run(0, m, scatter_start[0].data());
  } else {
    detail::run_parts(2, [&](int part) {
      std::uint32_t* ps = scatter_start[part].data();
      const std::size_t b = part == 0 ? 0 : split, e = part == 0 ? split : m;
      if (combine)
        run_combined(b, e, ps);
      else
        run(b, e, ps);
    });
  }
  if (to < nb || stop) return;
  const SphereTable& t = *table;
  // The key range: q is monotone in lo, so the extremes lie in the first and last non-empty buckets.
  std::size_t first = 0, last = nb - 1;
  while (bucket_begin[first + 1] == 0) ++first;
  while (bucket_begin[last] == m) --last;
  double kmin = std::numeric_limits<double>::infinity(), kmax = -kmin;
  for (std::size_t b : {first, last})
    for (std::size_t i = bucket_begin[b]; i < bucket_begin[b + 1]; ++i) {
      const std::uint32_t rep = rep_tet(t, item_of(sorted[i]));
      const double lo = lo_of(rep, radius_of(rep));
      kmin = std::min(kmin, lo);
      kmax = std::max(kmax, lo);
    }
  key_range_found = kmax - kmin;
}

// Sorts one first-level bucket [begin, end) by packed value: a counting pass over n to 2n
// sub-buckets of the q bits below the first level's (mostly empty or single, so that the insertion
// pass that follows mispredicts little; 2n to 4n measured 12% slower: more counters to clear and
// sum), then the insertion pass.
void ProgressiveOrder::Impl::sort_bucket(std::size_t begin, std::size_t end, Scratch& sc) {
  if (prefetch_ties)
    sort_bucket_of<true>(begin, end, sc);
  else
    sort_bucket_of<false>(begin, end, sc);
}

template <bool kFetch>
void ProgressiveOrder::Impl::sort_bucket_of(std::size_t begin, std::size_t end, Scratch& sc) {
  Packed* a = sorted.data() + begin;
  const std::size_t n = end - begin;
  auto insertion = [](Packed* x, std::size_t len) {
    for (std::size_t i = 1; i < len; ++i) {
      const Packed v = x[i];
      std::size_t j = i;
      for (; j > 0 && v < x[j - 1]; --j) x[j] = x[j - 1];
      x[j] = v;
    }
  };
  if (n <= 32) {
    insertion(a, n);
    if (kFetch) prefetch_near_ties(begin, end);
    return;
  }
  int sub_bits = 1;
  while ((std::size_t(1) << sub_bits) < n && sub_bits < bucket_shift) ++sub_bits;
  const int sub_shift = bucket_shift - sub_bits;
  const std::uint32_t mask = (std::uint32_t(1) << sub_bits) - 1;
  const std::size_t subs = std::size_t(1) << sub_bits;
  sc.counts.assign(subs + 1, 0);
  if (sc.tmp.size() < n) sc.tmp.resize(n);
  std::uint32_t* cnt = sc.counts.data();
  Packed* tmp = sc.tmp.data();
  for (std::size_t i = 0; i < n; ++i) ++cnt[((q_of(a[i]) >> sub_shift) & mask) + 1];
  std::uint32_t acc = 0;  // the running sum in a register, not through memory
  for (std::size_t k = 1; k <= subs; ++k) {
    acc += cnt[k];
    cnt[k] = acc;
  }
  for (std::size_t i = 0; i < n; ++i) tmp[cnt[(q_of(a[i]) >> sub_shift) & mask]++] = a[i];
  // Back into place by one insertion pass (nothing moves across sub-buckets), with a budget of
  // moves: keys crowded into a few sub-buckets go to std::sort instead.
  // Most entries are alone in their sub-bucket and come in order: that case is one compare. The
  // near ties' keys are fetched on the way (a pair found here may still be parted by a later
  // insertion, or one missed: a prefetch is only a hint).
  std::size_t budget = 4 * n;
  a[0] = tmp[0];
  for (std::size_t i = 1; i < n; ++i) {
    const Packed v = tmp[i];
    if (!(v < a[i - 1])) {
      if (kFetch) prefetch_if_tie(a[i - 1], v);
      a[i] = v;
      continue;
    }
    std::size_t j = i;
    do {
      a[j] = a[j - 1];
      --j;
    } while (j > 0 && v < a[j - 1]);
    a[j] = v;
    if (kFetch) {
      prefetch_if_tie(v, a[j + 1]);
      if (j > 0) prefetch_if_tie(a[j - 1], v);
    }
    budget -= std::min(budget, i - j);
    if (budget == 0) {
      std::copy(tmp + i + 1, tmp + n, a + i + 1);
      std::sort(a, a + n);
      if (kFetch) prefetch_near_ties(begin, end);
      break;
    }
  }
}

// Every entry stands for an interval [lo, lo + 2 radius] holding its exact key (drawing order);
// two entries can be out of order only if their intervals overlap, and then they are joined in q
// order. A maximal run of joined neighbours is re-sorted by lo (recomputed in double), and within it
// the chains of overlapping intervals by exact comparison (made only for overlapping pairs).
void ProgressiveOrder::Impl::resolve_run(std::size_t begin, std::size_t end, Scratch& sc) {
  std::vector<Entry>& run = sc.run;
  run.clear();
  // Split clusters (see SphereTable::clusters_split): their tets tie exactly, so all of a
  // cluster's tets are in this run; each cluster becomes one entry, the first of its tets met
  // (with that tet's own interval), expanded below. (A cluster not wholly here, which the bounds
  // rule out, would stay as separate tets.)
  auto& clusters = sc.run_clusters;
  clusters.clear();
  auto cluster_at = [&](std::uint32_t k) {
    return std::find_if(clusters.begin(), clusters.end(), [k](const auto& c) { return c.first == k; });
  };
  if (split_clusters) {
    for (std::size_t k = begin; k < end; ++k) {
      const std::uint32_t c = table->cluster_of[item_of(sorted[k])];
      if (c == kNone) continue;
      auto at = cluster_at(c);
      if (at == clusters.end())
        clusters.emplace_back(c, 1);
      else
        ++at->second;
    }
    for (auto& [c, count] : clusters)
      if (count != table->cluster_begin[c + 1] - table->cluster_begin[c]) count = 0;  // not wholly here
  }
  for (std::size_t k = begin; k < end; ++k) {
    std::uint32_t item = item_of(sorted[k]);
    const std::uint32_t rep = rep_tet(*table, item);
    if (!clusters.empty() && table->cluster_of[rep] != kNone) {
      auto at = cluster_at(table->cluster_of[rep]);
      if (at->second == kNone) continue;  // its cluster's entry is in the run already
      if (at->second != 0) {
        item = at->first | kClusterBit;
        at->second = kNone;
      }
    }
    const float r = radius_of(rep, double_bound);
    run.push_back({lo_of(rep, r), r, item});
  }
  // By (lo, item): the same order whatever order the run came in.
  std::sort(run.begin(), run.end(),
            [](const Entry& x, const Entry& y) { return x.lo < y.lo || (x.lo == y.lo && x.item < y.item); });
  std::size_t i = 0;
  const std::size_t n = run.size();
  while (i < n) {
    double reach = run[i].hi();
    std::size_t j = i;
    while (j + 1 < n && run[j + 1].lo <= reach) reach = std::max(reach, run[++j].hi());
    if (j > i) {
      // Distinct items may still share a sphere (not face-adjacent): exact equality leaves them in
      // any order, which is then correct (they are incomparable, Theorem 1).
      struct Exact {
        Entry e;
        mutable std::unique_ptr<exact::PowerKey> key;
      };
      std::vector<Exact> chain;
      chain.reserve(j - i + 1);
      for (std::size_t k = i; k <= j; ++k) chain.push_back({run[k], nullptr});
      auto exact_of = [&](const Exact& x) -> const exact::PowerKey& {
        if (!x.key) {
          x.key = std::make_unique<exact::PowerKey>();
          exact_key(*mesh, *table, view, rep_tet(*table, x.e.item), *x.key);
        }
        return *x.key;
      };
      const bool ftb = front_to_back;
      std::stable_sort(chain.begin(), chain.end(), [&](const Exact& x, const Exact& y) {
        if (x.e.hi() < y.e.lo) return true;
        if (y.e.hi() < x.e.lo) return false;
        int c = exact_of(x).compare(exact_of(y));
        return ftb ? c < 0 : c > 0;
      });
      for (std::size_t k = i; k <= j; ++k) run[k] = chain[k - i].e;
      ++sc.near_tie_runs;
      sc.near_tie_items += j - i + 1;
    }
    i = j + 1;
  }
  // The items in their order; the q values stay where they were (ascending).
  if (clusters.empty()) {
    for (std::size_t k = begin; k < end; ++k)
      sorted[k] = (sorted[k] & ~Packed(0xFFFFFFFFu)) | run[k - begin].item;
    return;
  }
  std::size_t k = begin;
  for (const Entry& e : run) {
    if (!(e.item & kClusterBit)) {
      sorted[k] = (sorted[k] & ~Packed(0xFFFFFFFFu)) | e.item;
      ++k;
      continue;
    }
    const std::uint32_t c = e.item & ~kClusterBit;
    sc.cluster_out.resize(table->cluster_begin[c + 1] - table->cluster_begin[c]);
    std::uint32_t* o = sc.cluster_out.data();
    expand(e.item, o, sc);
    for (std::uint32_t tet : sc.cluster_out) {
      sorted[k] = (sorted[k] & ~Packed(0xFFFFFFFFu)) | tet;
      ++k;
    }
  }
}

template <bool kStream>
std::uint32_t* ProgressiveOrder::Impl::emit_tets(std::size_t begin, std::size_t end, std::uint32_t* o,
                                                 Scratch& sc) {
  auto put = [](std::uint32_t* at, std::uint32_t item) {
    if constexpr (kStream)
      store_item(at, item);
    else
      *at = item;
  };
  const Packed* a = sorted.data();
  const std::uint64_t w = q_window;
  for (std::size_t i = begin; i + 1 < end; ++i) {
    if (std::uint64_t(q_of(a[i + 1])) - q_of(a[i]) > w) {
      put(o++, item_of(a[i]));
      continue;
    }
    std::size_t j = i + 1;
    while (j + 1 < end && std::uint64_t(q_of(a[j + 1])) - q_of(a[j]) <= w) ++j;
    resolve_run(i, j + 1, sc);
    for (; i < j; ++i) put(o++, item_of(a[i]));
    if (i + 1 == end) break;
    put(o++, item_of(a[i]));
  }
  if (end > begin) put(o++, item_of(a[end - 1]));
  return o;
}

// Appends the tets of one item: a tet, or a cluster in its local MPVO order for the view.
void ProgressiveOrder::Impl::expand(std::uint32_t item, std::uint32_t*& o, Scratch& sc) {
  auto& local_tets = sc.local_tets;
  auto& local_indeg = sc.local_indeg;
  auto& local_queue = sc.local_queue;
  auto& local_edges = sc.local_edges;
  if (!(item & kClusterBit)) {
    *o++ = item;
    return;
  }
  const SphereTable& t = *table;
  const std::uint32_t k = item & ~kClusterBit;
  const std::uint32_t cb = t.cluster_begin[k], ce = t.cluster_begin[k + 1];
  if (ce - cb <= 64) {
    // Small cells (a grid cube: 5 or 6 tets): predecessor bit masks, planes tested in double with a
    // rounding bound, exact orientation only when in doubt.
    std::uint64_t pred[64];
    std::uint64_t emitted = 0, hidden = 0;
    const std::uint32_t size = ce - cb;
    std::fill(pred, pred + size, std::uint64_t(0));
    // Tets outside the subset are not drawn but keep their constraints: the cluster's order holds
    // through them (a subset of a cluster need not be convex; two of its tets may face each other
    // across one left out).
    if (!in_subset.empty())
      for (std::uint32_t i = 0; i < size; ++i)
        if (!in_subset[t.cluster_tets[cb + i]]) hidden |= std::uint64_t(1) << i;
    const bool persp = view.perspective;
    const double* e = view.eye;
    const double back[3] = {-view.dir[0], -view.dir[1], -view.dir[2]};
    const double en = persp ? std::abs(e[0]) + std::abs(e[1]) + std::abs(e[2])
                            : std::abs(back[0]) + std::abs(back[1]) + std::abs(back[2]);
    for (std::uint32_t f = t.cluster_face_begin[k]; f < t.cluster_face_begin[k + 1]; ++f) {
      const SphereTable::ClusterFace& ft = t.face_test[f];
      const std::uint32_t a = ft.local[0], b = ft.local[1];
      const double* pl = ft.plane;
      double val, err;
      if (persp) {
        val = pl[0] * e[0] + pl[1] * e[1] + pl[2] * e[2] - pl[3];
        err = 96 * kEps * double(ft.scale) * (en + double(ft.anorm));
      } else {
        val = pl[0] * back[0] + pl[1] * back[1] + pl[2] * back[2];
        err = 32 * kEps * double(ft.scale) * en;
      }
      int side = val > err ? 1 : val < -err ? -1 : 2;
      if (side == 2) {
        const std::uint32_t* fv = t.face_vertex.data() + 3 * std::size_t(f);
        side = eye_side(view, node(*mesh, fv[0]), node(*mesh, fv[1]), node(*mesh, fv[2]));
      }
      if (side == 0) continue;
      if (ft.separating && !rays_meet_both(view, *mesh, t.cluster_tets[cb + a], t.cluster_tets[cb + b]))
        continue;
      // Tet a lies on the positive side. Eye there: a is in front, so b comes first (back to front).
      std::uint32_t first = side > 0 ? b : a, second = side > 0 ? a : b;
      if (front_to_back) std::swap(first, second);
      pred[second] |= std::uint64_t(1) << first;
    }
    const std::uint64_t all = size == 64 ? ~std::uint64_t(0) : (std::uint64_t(1) << size) - 1;
    while (emitted != all) {
      std::uint32_t pick = 64;
      for (std::uint32_t i = 0; i < size; ++i)
        if (!(emitted >> i & 1) && (pred[i] & ~emitted) == 0) {
          pick = i;
          break;
        }
      if (pick == 64) {
        // A cycle (not possible in a Delaunay cell seen from a generic point): break it.
        ++sc.cluster_cycles;
        for (std::uint32_t i = 0; i < size; ++i)
          if (!(emitted >> i & 1)) {
            pick = i;
            break;
          }
      }
      emitted |= std::uint64_t(1) << pick;
      if (!(hidden >> pick & 1)) *o++ = t.cluster_tets[cb + pick];
    }
    return;
  }
  // All the cluster's tets, those outside the subset too (their constraints hold the order, as
  // above), written out only if in the subset.
  local_tets.assign(t.cluster_tets.begin() + cb, t.cluster_tets.begin() + ce);
  auto local_index = [&](std::uint32_t tet) -> std::uint32_t {
    for (std::uint32_t i = 0; i < local_tets.size(); ++i)
      if (local_tets[i] == tet) return i;
    return kNone;
  };
  local_edges.clear();
  local_indeg.assign(local_tets.size(), 0);
  for (std::uint32_t f = t.cluster_face_begin[k]; f < t.cluster_face_begin[k + 1]; ++f) {
    std::uint32_t a = local_index(t.face_tet[2 * f]), b = local_index(t.face_tet[2 * f + 1]);
    if (a == kNone || b == kNone) continue;
    const std::uint32_t* fv = t.face_vertex.data() + 3 * std::size_t(f);
    int side = eye_side(view, node(*mesh, fv[0]), node(*mesh, fv[1]), node(*mesh, fv[2]));
    if (side == 0) continue;
    // Tet a lies on the positive side. Eye there: a is in front, so b comes first (back to front).
    std::uint32_t first = side > 0 ? b : a, second = side > 0 ? a : b;
    if (front_to_back) std::swap(first, second);
    local_edges.emplace_back(first, second);
    ++local_indeg[second];
  }
  local_queue.clear();
  sc.local_done.assign(local_tets.size(), 0);
  auto& done = sc.local_done;
  std::size_t emitted = 0;
  for (std::uint32_t i = 0; i < local_tets.size(); ++i)
    if (local_indeg[i] == 0) local_queue.push_back(i);
  while (emitted < local_tets.size()) {
    if (local_queue.empty()) {
      // A cycle (not possible in a Delaunay cell seen from a generic point): break it.
      ++sc.cluster_cycles;
      for (std::uint32_t i = 0; i < local_tets.size(); ++i)
        if (!done[i]) {
          local_queue.push_back(i);
          local_indeg[i] = 0;
          break;
        }
    }
    std::uint32_t x = local_queue.back();
    local_queue.pop_back();
    if (done[x]) continue;
    done[x] = 1;
    ++emitted;
    if (tet_in(local_tets[x])) *o++ = local_tets[x];
    for (auto& e : local_edges)
      if (e.first == x && !done[e.second] && --local_indeg[e.second] == 0) local_queue.push_back(e.second);
  }
}

ProgressiveOrder::ProgressiveOrder(const MeshView& mesh, const SphereTable& table, const View& view,
                                   std::span<const std::uint32_t> subset, bool front_to_back)
    : impl_(std::make_unique<Impl>()) {
  impl_->mesh_view = mesh;
  impl_->mesh = &impl_->mesh_view;
  impl_->table = &table;
  impl_->view = view;
  impl_->front_to_back = front_to_back;
  impl_->prepare(subset, true);
}

ProgressiveOrder::~ProgressiveOrder() = default;
ProgressiveOrder::ProgressiveOrder(ProgressiveOrder&&) noexcept = default;
ProgressiveOrder& ProgressiveOrder::operator=(ProgressiveOrder&&) noexcept = default;

std::size_t ProgressiveOrder::Impl::emit_buckets(std::size_t first, std::size_t last, std::size_t limit,
                                                 std::vector<std::uint32_t>& out, Scratch& sc,
                                                 std::uint32_t* direct) {
  // Sorts bucket k unless this thread has sorted it ahead (a bucket once emitted has its near
  // ties resolved, which a second sort would undo, so each is sorted once).
  auto ensure_sorted = [&](std::size_t k) {
    if (k < sc.sorted_upto && k >= first) return;
    sort_bucket(bucket_begin[k], bucket_begin[k + 1], sc);
    sc.sorted_upto = k + 1;
  };
  // A whole order beyond the cache is written around it (the caller's buffer, read next by the
  // drawing, from memory either way).
  const bool stream_out = direct != nullptr && stream_entries(bucket_begin.back());
  std::size_t b = first;
  while (b < last) {
    const std::size_t group = b;  // the first bucket of this group
    const std::size_t begin = bucket_begin[b];
    std::size_t end = bucket_begin[b + 1];
    ++b;
    if (begin == end) continue;
    ensure_sorted(group);
    // A run of joined entries may cross into the following buckets: take them in while it may.
    // Bucket b holds no q below b << bucket_shift, so most checks need not look into it.
    while (b < limit) {
      const std::size_t nb_begin = bucket_begin[b], nb_end = bucket_begin[b + 1];
      if (nb_begin == nb_end) {
        ++b;
        continue;
      }
      const Packed bucket_low = Packed(b) << (32 + bucket_shift);
      if (!joined(sorted[end - 1], bucket_low)) break;
      ensure_sorted(b);
      if (!joined(sorted[end - 1], sorted[nb_begin])) break;  // sorted now, handed out next
      end = nb_end;
      ++b;
    }
    // The next bucket sorted now and its near ties' keys fetched, arriving while this group is
    // scanned (one group after another, each resolve_run would wait for its misses).
    std::size_t ahead = b;
    while (ahead < limit && bucket_begin[ahead] == bucket_begin[ahead + 1]) ++ahead;
    if (prefetch_ties && ahead < limit && ahead >= sc.sorted_upto) ensure_sorted(ahead);
    const std::uint32_t* tb = t_cluster_free ? bucket_begin.data() : tet_begin.data();
    std::uint32_t* o;  // (no offset added to a null `direct`: undefined, UBSan's pointer-overflow check)
    if (direct == nullptr) {
      const std::size_t at = out.size();
      out.resize(at + (tb[b] - tb[group]));
      o = out.data() + at;
    } else {
      o = direct + tb[group];
    }
    if (t_cluster_free && zones.empty()) {
      o = stream_out ? emit_tets<true>(begin, end, o, sc) : emit_tets<false>(begin, end, o, sc);
    } else if (t_cluster_free && stream_out) {
      scan_runs(begin, end, sc, [&o](std::uint32_t item) { store_item(o++, item); });
    } else if (t_cluster_free) {
      scan_runs(begin, end, sc, [&o](std::uint32_t item) { *o++ = item; });
    } else {
      // Clusters met in key order are scattered over memory, and each expansion is a chain of
      // dependent cache misses (offsets, then faces): the offsets of the cluster kFar items ahead
      // and the faces and tets of the one kNear ahead are fetched as each item is expanded, so
      // that a bounded number of misses overlap (a whole group fetched at once overflows L1).
      constexpr std::size_t kNear = 8, kFar = 24;
      const Packed* a = sorted.data();
      std::size_t at = begin, near = begin, far = begin;
      auto fetch_ahead = [&] {
        for (; far < end && far < at + kFar; ++far) prefetch_offsets(item_of(a[far]));
        for (; near < end && near < at + kNear; ++near) prefetch_cluster(item_of(a[near]));
        ++at;
      };
      if (many_clusters) {
        scan_runs(begin, end, sc, [&](std::uint32_t item) {
          fetch_ahead();
          if (item & kClusterBit)
            expand(item, o, sc);
          else
            *o++ = item;
        });
      } else {
        scan_runs(begin, end, sc, [&](std::uint32_t item) {
          if (item & kClusterBit)
            expand(item, o, sc);
          else
            *o++ = item;
        });
      }
    }
  }
  if (stream_out) store_fence();
  return b;
}

void ProgressiveOrder::Impl::hand_out_head() {
  const std::size_t at = bucket_begin[head_buckets];
  // Every head entry to its bucket (a counting scatter over the few head buckets, whose sizes
  // bucket_begin holds); emit_buckets sorts each bucket.
  std::vector<std::uint32_t> slot(bucket_begin.begin(), bucket_begin.begin() + std::ptrdiff_t(head_buckets));
  Packed* dst = sorted.data();
  for (int part = 0; part < 2; ++part)
    for (std::size_t i = 0; i < head_count[part]; ++i) {
      const Packed p = head[part][i];
      dst[slot[q_of(p) >> bucket_shift]++] = p;
    }
  scatter_from = head_buckets;
  const std::size_t counts[3] = {scratch.near_tie_runs, scratch.near_tie_items, scratch.cluster_cycles};
  next_bucket = emit_buckets(0, head_buckets, head_buckets, batch, scratch);
  if (at > 0 && joined(sorted[at - 1], Packed(head_buckets) << (32 + bucket_shift))) {
    // A run of joined entries may go on past the head: the worker hands it all out in order.
    batch.clear();
    next_bucket = 0;
    scratch.near_tie_runs = counts[0];
    scratch.near_tie_items = counts[1];
    scratch.cluster_cycles = counts[2];
  }
}

void ProgressiveOrder::Impl::run_worker() {
  const std::size_t nb = bucket_begin.size() - 1;
  std::size_t b = next_bucket;
  bool first = true;
  std::vector<std::uint32_t> pending;
  auto hand_out = [&] {
    first = false;
    std::lock_guard<std::mutex> g(mu);
    ready.push_back(std::move(pending));
    pending.clear();
    cv.notify_one();
  };
  first = b == 0;
  if (keys_deferred && !deferred_key_pass()) b = nb;  // stopped
  if (!scattered && b < nb) {
    scatter(scatter_from, nb);
    scattered = true;
  }
  while (b < nb && !stop) {
    b = emit_buckets(b, b + 1, nb, pending, scratch);
    // The first bucket goes out at once; later ones in batches of a few thousand tets.
    if (!pending.empty() && (first || pending.size() >= 4096 || b >= nb)) hand_out();
  }
  std::lock_guard<std::mutex> g(mu);
  if (!pending.empty()) ready.push_back(std::move(pending));
  next_bucket = b;
  worker_done = true;
  cv.notify_one();
}

std::span<const std::uint32_t> ProgressiveOrder::next() {
  Impl& d = *impl_;
  d.batch.clear();
  // (bucket_begin is the worker's while it runs: only its size is read here.)
  const std::size_t nb = d.bucket_begin.size() - 1;
  if (d.item_count < 50000) {
    // Small orders: on this thread, bucket by bucket.
    if (!d.scattered) {
      d.scatter(0, nb);
      d.scattered = true;
    }
    while (d.batch.empty() && d.next_bucket < nb)
      d.next_bucket = d.emit_buckets(d.next_bucket, d.next_bucket + 1, nb, d.batch, d.scratch);
    d.add_counts(d.scratch);
  } else {
    if (!d.worker.valid() && !d.worker_done) {
      // The head buckets here, at once; the rest is placed and sorted ahead by the worker.
      if (d.head_fits) d.hand_out_head();
      d.worker = detail::run_async([&d] {
        try {
          d.run_worker();
        } catch (...) {
          // Wake the caller, which rethrows it from the future.
          std::lock_guard<std::mutex> g(d.mu);
          d.worker_done = true;
          d.cv.notify_one();
          throw;
        }
      });
      if (!d.batch.empty()) {
        d.handed += d.batch.size();
        return d.batch;
      }
    }
    std::unique_lock<std::mutex> lock(d.mu);
    d.cv.wait(lock, [&d] { return !d.ready.empty() || d.worker_done; });
    if (!d.ready.empty()) {
      d.batch.swap(d.ready.front());
      d.ready.pop_front();
    }
    if (d.ready.empty() && d.worker_done) {
      lock.unlock();
      if (d.worker.valid()) d.worker.get();
      d.add_counts(d.scratch);
    }
  }
  d.handed += d.batch.size();
  return d.batch;
}

std::size_t ProgressiveOrder::handed_out() const { return impl_->handed; }
std::size_t ProgressiveOrder::total() const { return impl_->total_tets; }
const OrderStats& ProgressiveOrder::stats() const { return impl_->stats; }

std::vector<std::uint32_t> visibility_order(const MeshView& mesh, const SphereTable& table, const View& view,
                                            std::span<const std::uint32_t> subset, bool front_to_back,
                                            OrderStats* stats) {
  std::vector<std::uint32_t> out;
  visibility_order_into(out, mesh, table, view, subset, front_to_back, stats);
  return out;
}

void visibility_order_into(std::vector<std::uint32_t>& out, const MeshView& mesh, const SphereTable& table,
                           const View& view, std::span<const std::uint32_t> subset, bool front_to_back,
                           OrderStats* stats) {
  using Clock = std::chrono::steady_clock;
  const Clock::time_point t0 = Clock::now();
  ProgressiveOrder::Impl d;
  d.mesh = &mesh;
  d.table = &table;
  d.view = view;
  d.front_to_back = front_to_back;
  d.prepare(subset, false);
  const Clock::time_point t1 = Clock::now();
  const std::size_t nb = d.bucket_begin.size() - 1;
  d.scatter(0, nb);
  d.scattered = true;
  const Clock::time_point t2 = Clock::now();
  // Every bucket's tets go straight to their final places.
  out.resize(d.total_tets);
  std::uint32_t* direct = out.data();
  // Both cores: the first half of the buckets here, the second half on another thread. A tie chain
  // across the split (rare) sends everything back through one thread.
  std::size_t split = 0;
  const std::size_t m = d.bucket_begin[nb];
  if (m >= 100000) {
    split = static_cast<std::size_t>(
        std::lower_bound(d.bucket_begin.begin(), d.bucket_begin.end(), static_cast<std::uint32_t>(m / 2)) -
        d.bucket_begin.begin());
    if (split >= nb) split = 0;
  }
  bool done = false;
  if (split > 0) {
    ProgressiveOrder::Impl::Scratch other_scratch;
    detail::run_parts(2, [&](int part) {
      if (part == 0)
        d.emit_buckets(0, split, split, out, d.scratch, direct);
      else
        d.emit_buckets(split, nb, nb, out, other_scratch, direct);
    });
    // The halves are independent unless the last entry of the first joins the first of the second.
    const std::size_t at = d.bucket_begin[split];
    if (at == 0 || at == m || !d.joined(d.sorted[at - 1], d.sorted[at])) {
      d.add_counts(d.scratch);
      d.add_counts(other_scratch);
      done = true;
    } else {
      d.scratch = {};
    }
  }
  if (!done) {
    d.emit_buckets(0, nb, nb, out, d.scratch, direct);
    d.add_counts(d.scratch);
  }
  d.next_bucket = nb;
  d.handed = out.size();
  d.stats.keys_seconds = std::chrono::duration<double>(t1 - t0).count();
  d.stats.scatter_seconds = std::chrono::duration<double>(t2 - t1).count();
  d.stats.sort_seconds = std::chrono::duration<double>(Clock::now() - t2).count();
  if (stats) *stats = d.stats;
}

}  // namespace foxi
