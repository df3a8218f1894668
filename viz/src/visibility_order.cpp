#include "foxi/viz/visibility_order.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <condition_variable>
#include <deque>
#include <limits>
#include <mutex>
#include <queue>
#include <thread>

#include "exact.hpp"
#include "foxi/model/adjacency.hpp"

namespace foxi {

namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();

// Face f of a positively oriented tet, listed so that the tet's own vertex f is on its negative side.
constexpr int kFace[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};

template <class F>
void parallel_for(std::size_t n, F f) {
  if (n < 50000) {
    f(std::size_t{0}, n, 0);
    return;
  }
  std::size_t half = n / 2;
  std::thread other([&] { f(half, n, 1); });
  f(std::size_t{0}, half, 0);
  other.join();
}

const double* node(const Mesh& m, std::uint32_t v) { return m.xyz.data() + 3 * std::size_t(v); }

// +1: the eye is on the positive side of triangle (a, b, c); -1 negative; 0 on its plane.
// orient3d(a, b, c, p) in double with Shewchuk's error bound; the exact predicate when in doubt.
inline int fast_orientation(const double* a, const double* b, const double* c, const double* p) {
  const double adx = a[0] - p[0], bdx = b[0] - p[0], cdx = c[0] - p[0];
  const double ady = a[1] - p[1], bdy = b[1] - p[1], cdy = c[1] - p[1];
  const double adz = a[2] - p[2], bdz = b[2] - p[2], cdz = c[2] - p[2];
  const double bdxcdy = bdx * cdy, cdxbdy = cdx * bdy;
  const double cdxady = cdx * ady, adxcdy = adx * cdy;
  const double adxbdy = adx * bdy, bdxady = bdx * ady;
  const double det = adz * (bdxcdy - cdxbdy) + bdz * (cdxady - adxcdy) + cdz * (adxbdy - bdxady);
  const double permanent = (std::abs(bdxcdy) + std::abs(cdxbdy)) * std::abs(adz) +
                           (std::abs(cdxady) + std::abs(adxcdy)) * std::abs(bdz) +
                           (std::abs(adxbdy) + std::abs(bdxady)) * std::abs(cdz);
  const double bound = (7.0 * kEps / 2 + 56.0 * kEps * kEps / 4) * permanent;  // o3derrboundA
  // Shewchuk's orient3d is positive when p is below (a, b, c); ours is det[b-a, c-a, p-a].
  if (det > bound) return -1;
  if (-det > bound) return 1;
  return exact::orientation(a, b, c, p);
}

int eye_side(const View& view, const double* a, const double* b, const double* c) {
  if (view.perspective) return fast_orientation(a, b, c, view.eye);
  const double back[3] = {-view.dir[0], -view.dir[1], -view.dir[2]};
  return exact::orientation_at_infinity(a, b, c, back);
}

std::uint32_t rep_tet(const SphereTable& t, std::uint32_t item) {
  return (item & kClusterBit) ? t.cluster_tets[t.cluster_begin[item & ~kClusterBit]] : item;
}

void exact_key(const Mesh& m, const SphereTable& table, const View& view, std::uint32_t tet, exact::PowerKey& key) {
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

// One sort entry: the item's key in drawing order (ascending = drawn first) minus its rounding
// radius, so that the exact key lies in [lo, lo + 2 radius].
struct Entry {
  double lo;
  float radius;
  std::uint32_t item;
  double hi() const { return lo + 2.0 * double(radius); }
  bool operator<(const Entry& o) const { return lo < o.lo; }
};

// Buffers reused from one view to the next on the same thread (no page faults, no zeroing).
struct Workspace {
  std::vector<double> lo;       // pass 1: each item's lo (8 bytes per item)
  std::vector<Entry> entries;   // the bucketed entries (16 bytes per item)
};
thread_local Workspace t_workspace;

struct ProgressiveOrder::Impl {
  const Mesh* mesh = nullptr;
  const SphereTable* table = nullptr;
  View view;
  bool front_to_back = false;
  std::vector<std::uint8_t> in_subset;          // per tet, only when a subset meets clusters
  std::vector<Entry> sorted;                    // bucketed; each bucket sorted when handed out
  std::vector<std::uint32_t> bucket_begin;      // size buckets + 1
  std::size_t next_bucket = 0;
  std::vector<std::uint32_t> batch;
  std::size_t handed = 0, total_tets = 0;
  OrderStats stats;
  // Per-thread scratch: the local MPVO of clusters and the tie counts.
  struct Scratch {
    std::vector<std::uint32_t> local_tets, local_indeg, local_queue;
    std::vector<std::pair<std::uint32_t, std::uint32_t>> local_edges;
    std::vector<std::uint8_t> local_done;
    std::vector<Entry> tmp;            // the second-level counting sort
    std::vector<std::uint32_t> counts, subs;
    std::size_t near_tie_runs = 0, near_tie_items = 0, cluster_cycles = 0;
  };
  Scratch scratch;
  void add_counts(Scratch& sc) {
    stats.near_tie_runs += sc.near_tie_runs;
    stats.near_tie_items += sc.near_tie_items;
    stats.cluster_cycles += sc.cluster_cycles;
    sc.near_tie_runs = sc.near_tie_items = sc.cluster_cycles = 0;
  }

  bool tet_in(std::uint32_t t) const { return in_subset.empty() || in_subset[t]; }

  // The progressive path sorts ahead on a second thread (started by the first next()), so that the
  // caller can draw one batch while the next buckets are being sorted.
  std::thread worker;
  std::mutex mu;
  std::condition_variable cv;
  std::deque<std::vector<std::uint32_t>> ready;
  bool worker_done = false;
  std::atomic<bool> stop{false};
  void run_worker();

  ~Impl() {
    if (worker.joinable()) {
      stop = true;
      worker.join();
    }
    // Hand the big buffer back for the next view on this thread. (A buffer the worker thread made
    // is the same memory; the thread_local slot is this thread's.)
    if (sorted.capacity() > t_workspace.entries.capacity()) t_workspace.entries.swap(sorted);
  }
  void prepare(std::span<const std::uint32_t> subset);
  // Re-sorts the near-tie chains of [begin, end) exactly; returns the high end of the last chain and
  // sets *last_chain to where it starts.
  double fix_ties(std::size_t begin, std::size_t end, Scratch& sc, std::size_t* last_chain);
  // Sorts [begin, end) by lo; `bucket` is the first-level bucket it is (its key range is known), or
  // kNone for a range whose bounds must be scanned.
  void sort_bucket(std::size_t begin, std::size_t end, Scratch& sc, std::size_t bucket);
  double bucket_low(std::size_t b) const { return bucket_min + double(b) / bucket_scale; }
  double bucket_min = 0, bucket_scale = 0;  // the linear map of lo to first-level buckets
  bool t_cluster_free = false;              // no item is a cluster: copy items straight out
  void expand(std::uint32_t item, std::vector<std::uint32_t>& out, Scratch& sc);
  // Hands out buckets [first, last) into out (sorting, tie fix-up, cluster expansion); returns the
  // next bucket not consumed: a tie chain may take in buckets from `last` up to `limit`. *reach_out
  // receives the high end of the last entry's chain.
  std::size_t emit_buckets(std::size_t first, std::size_t last, std::size_t limit, std::vector<std::uint32_t>& out,
                           Scratch& sc, double* reach_out);
};

void ProgressiveOrder::Impl::prepare(std::span<const std::uint32_t> subset) {
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
    std::vector<std::uint8_t> cluster_seen(t.cluster_count(), 0);
    own_items.reserve(subset.size());
    for (std::uint32_t tet : subset) {
      if (!in_subset.empty()) in_subset[tet] = 1;
      std::uint32_t k = t.cluster_of.empty() ? kNone : t.cluster_of[tet];
      std::uint32_t item = tet, rep = tet;
      if (k != kNone) {
        if (cluster_seen[k]) continue;
        cluster_seen[k] = 1;
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
  t_cluster_free = t.cluster_count() == 0;
  stats.items = m;
  stats.wide_items = wide_items.size();
  if (m == 0) {
    bucket_begin.assign(1, 0);
    return;
  }

  // Rounding bounds: |key error| <= a + b |p|_1 (orthographic: b |d|_1), in the local frame.
  View v = view;
  for (int k = 0; k < 3; ++k) v.eye[k] -= t.origin[k];
  const double np = v.perspective ? std::abs(v.eye[0]) + std::abs(v.eye[1]) + std::abs(v.eye[2])
                                  : std::abs(v.dir[0]) + std::abs(v.dir[1]) + std::abs(v.dir[2]);
  const double ka = v.perspective ? 1.0 : 0.0;
  // Rounded up to float, and a little more for the subtraction that places lo.
  const float bound = static_cast<float>((ka * t.bound_a + t.bound_b * np) * (1 + 1e-6));
  stats.key_bound = bound;

  // 1. Keys (both cores): each item's key in drawing order, placed at the low end of its interval.
  // Only lo is stored here (8 bytes); the 16-byte entries are made by the scatter, so a view needs
  // 24 bytes per item.
  std::vector<double>& los = t_workspace.lo;
  if (los.size() < m) los.resize(m);
  auto radius_of = [&](std::size_t i) {
    if (i < m_main) return bound;
    std::size_t w = i - m_main;
    return std::max(bound, static_cast<float>((ka * wide_a[w] + wide_b[w] * np) * (1 + 1e-6)));
  };
  const double* C = t.c.data();
  const double* S = t.s.data();
  const double sign = front_to_back ? 1.0 : -1.0;  // back to front: decreasing key first
  double lo_part[2] = {std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
  double hi_part[2] = {-lo_part[0], -lo_part[1]};
  // Tight loops on raw pointers: the ordinary items (no branch), then the few wide ones.
  const std::uint32_t* rep_p = reps.data();
  double* lo_p = los.data();
  const double px = 2 * v.eye[0], py = 2 * v.eye[1], pz = 2 * v.eye[2];
  const double dx = v.dir[0], dy = v.dir[1], dz = v.dir[2];
  const double shift = double(bound);
  parallel_for(m_main, [&](std::size_t b, std::size_t e, int part) {
    double l = lo_part[part], h = hi_part[part];
    if (v.perspective) {
      for (std::size_t i = b; i < e; ++i) {
        const std::size_t tet = rep_p[i];
        const double* c = C + 3 * tet;
        const double lo = sign * (S[tet] - (c[0] * px + c[1] * py + c[2] * pz)) - shift;
        lo_p[i] = lo;
        l = std::min(l, lo);
        h = std::max(h, lo);
      }
    } else {
      for (std::size_t i = b; i < e; ++i) {
        const double* c = C + 3 * std::size_t(rep_p[i]);
        const double lo = sign * (c[0] * dx + c[1] * dy + c[2] * dz) - shift;
        lo_p[i] = lo;
        l = std::min(l, lo);
        h = std::max(h, lo);
      }
    }
    lo_part[part] = l;
    hi_part[part] = h;
  });
  for (std::size_t i = m_main; i < m; ++i) {
    const std::uint32_t tet = rep_tet(t, wide_items[i - m_main]);
    const double* c = C + 3 * std::size_t(tet);
    const double k = v.perspective ? S[tet] - (c[0] * px + c[1] * py + c[2] * pz) : c[0] * dx + c[1] * dy + c[2] * dz;
    const double lo = sign * k - double(radius_of(i));
    lo_p[i] = lo;
    lo_part[0] = std::min(lo_part[0], lo);
    hi_part[0] = std::max(hi_part[0], lo);
  }
  double kmin = std::min(lo_part[0], lo_part[1]), kmax = std::max(hi_part[0], hi_part[1]);
  stats.key_range = kmax - kmin;
  // The buckets cover the bulk of the keys, [0.2%, 99.8%] quantiles of a sample, widened: keys
  // outside (far-flung spheres of slivers at the hull) fall into the first and last buckets.
  if (m > 4096) {
    std::vector<double> sample(1024);
    for (std::size_t i = 0; i < sample.size(); ++i) sample[i] = los[i * (m / sample.size())];
    std::sort(sample.begin(), sample.end());
    double qlo = sample[2], qhi = sample[sample.size() - 3], widen = 0.05 * (qhi - qlo);
    kmin = std::max(kmin, qlo - widen);
    kmax = std::min(kmax, qhi + widen);
  }

  // 2. The MSD bucket pass: a histogram and a scatter (both cores), by a linear map of lo.
  // Few enough buckets that the scatter stays in cache; each is sorted when handed out by a second
  // counting pass (sort_bucket).
  int bits = 4;
  while (bits < 16 && (std::size_t(256) << bits) < m) ++bits;
  const std::size_t nb = std::size_t(1) << bits;
  stats.buckets = nb;
  const double scale = kmax > kmin ? double(nb) / (kmax - kmin) : 0.0;
  bucket_min = kmin;
  bucket_scale = scale;
  const double last = double(nb - 1);
  auto bucket_of = [&](double lo) {
    double x = (lo - kmin) * scale;
    return x <= 0 ? 0u : x >= last ? static_cast<std::uint32_t>(last) : static_cast<std::uint32_t>(x);
  };
  std::vector<std::uint32_t> hist[2] = {std::vector<std::uint32_t>(nb, 0), std::vector<std::uint32_t>(nb, 0)};
  parallel_for(m, [&](std::size_t b, std::size_t e, int part) {
    std::uint32_t* h = hist[part].data();
    for (std::size_t i = b; i < e; ++i) ++h[bucket_of(lo_p[i])];
  });
  bucket_begin.assign(nb + 1, 0);
  std::vector<std::uint32_t> start0(nb), start1(nb);
  std::uint32_t acc = 0;
  for (std::size_t b = 0; b < nb; ++b) {
    bucket_begin[b] = acc;
    start0[b] = acc;
    acc += hist[0][b];
    start1[b] = acc;
    acc += hist[1][b];
  }
  bucket_begin[nb] = acc;
  sorted.swap(t_workspace.entries);
  if (sorted.size() < m) sorted.resize(m);
  std::vector<Entry>& out = sorted;
  const std::size_t split = m < 50000 ? m : m / 2;  // as parallel_for splits
  auto scatter = [&](std::size_t b, std::size_t e, std::vector<std::uint32_t>& pos) {
    std::uint32_t* ps = pos.data();
    Entry* o = out.data();
    const std::uint32_t* it = items.data();
    const std::size_t main_end = std::min(e, m_main);
    for (std::size_t i = b; i < main_end; ++i) {
      const double lo = lo_p[i];
      o[ps[bucket_of(lo)]++] = Entry{lo, bound, it[i]};
    }
    for (std::size_t i = std::max(b, m_main); i < e; ++i) {
      const double lo = lo_p[i];
      o[ps[bucket_of(lo)]++] = Entry{lo, radius_of(i), wide_items[i - m_main]};
    }
  };
  if (split == m) {
    scatter(0, m, start0);
  } else {
    std::thread other([&] { scatter(split, m, start1); });
    scatter(0, split, start0);
    other.join();
  }
}

// Sorts one bucket by lo: a counting pass over about n/2 sub-buckets of its own range, then an
// insertion sort over the nearly sorted result (linear for evenly spread keys).
void ProgressiveOrder::Impl::sort_bucket(std::size_t begin, std::size_t end, Scratch& sc, std::size_t bucket) {
  Entry* a = sorted.data() + begin;
  const std::size_t n = end - begin;
  const std::size_t nb = bucket_begin.size() - 1;
  if (n > 48) {
    double lo, hi;
    if (bucket != kNone && bucket > 0 && bucket + 1 < nb && bucket_scale > 0) {
      // Inner buckets: the linear map gives the range (entries just outside it by rounding land in
      // the end sub-buckets, and the insertion sort puts them right).
      lo = bucket_low(bucket);
      hi = bucket_low(bucket + 1);
    } else {
      lo = hi = a[0].lo;
      for (std::size_t i = 1; i < n; ++i) {
        lo = std::min(lo, a[i].lo);
        hi = std::max(hi, a[i].lo);
      }
    }
    if (hi > lo) {
      std::size_t subs = 1;
      while (subs < n / 2) subs <<= 1;
      const double sub_scale = double(subs) / (hi - lo) * (1 - 1e-12);
      sc.counts.assign(subs + 1, 0);
      if (sc.tmp.size() < n) sc.tmp.resize(n);
      if (sc.subs.size() < n) sc.subs.resize(n);
      const double top = double(subs - 1);
      std::uint32_t* cnt = sc.counts.data();
      std::uint32_t* sub = sc.subs.data();
      for (std::size_t i = 0; i < n; ++i) {
        const double f = (a[i].lo - lo) * sub_scale;
        const std::uint32_t k = static_cast<std::uint32_t>(std::clamp(f, 0.0, top));
        sub[i] = k;
        ++cnt[k + 1];
      }
      for (std::size_t k = 1; k <= subs; ++k) cnt[k] += cnt[k - 1];
      Entry* tmp = sc.tmp.data();
      for (std::size_t i = 0; i < n; ++i) tmp[cnt[sub[i]]++] = a[i];
      std::copy(tmp, tmp + n, a);
    }
  }
  for (std::size_t i = 1; i < n; ++i) {
    Entry x = a[i];
    std::size_t j = i;
    while (j > 0 && x.lo < a[j - 1].lo) {
      a[j] = a[j - 1];
      --j;
    }
    a[j] = x;
  }
}

// Every entry stands for an interval [lo, lo + 2 radius] holding its exact key (drawing order);
// two entries can be out of order only if their intervals overlap. Sorted by lo, the maximal chains
// of overlapping intervals are re-sorted by exact comparison (made only for overlapping pairs).
double ProgressiveOrder::Impl::fix_ties(std::size_t begin, std::size_t end, Scratch& sc, std::size_t* last_chain) {
  std::size_t i = begin;
  double reach = -std::numeric_limits<double>::infinity();
  *last_chain = begin;
  const Entry* a = sorted.data();
  while (i < end) {
    // Fast path: entries whose interval ends before the next one starts (almost all of them).
    while (i + 1 < end && a[i + 1].lo > a[i].hi()) ++i;
    std::size_t j = i;
    reach = sorted[i].hi();
    while (j + 1 < end && sorted[j + 1].lo <= reach) reach = std::max(reach, sorted[++j].hi());
    if (j > i) {
      // Distinct items may still share a sphere (not face-adjacent): exact equality leaves them in
      // any order, which is then correct (they are incomparable, Theorem 1).
      struct Run {
        Entry e;
        mutable std::unique_ptr<exact::PowerKey> key;
      };
      std::vector<Run> run;
      run.reserve(j - i + 1);
      for (std::size_t k = i; k <= j; ++k) run.push_back({sorted[k], nullptr});
      auto exact_of = [&](const Run& r) -> const exact::PowerKey& {
        if (!r.key) {
          r.key = std::make_unique<exact::PowerKey>();
          exact_key(*mesh, *table, view, rep_tet(*table, r.e.item), *r.key);
        }
        return *r.key;
      };
      const bool ftb = front_to_back;
      std::stable_sort(run.begin(), run.end(), [&](const Run& x, const Run& y) {
        if (x.e.hi() < y.e.lo) return true;
        if (y.e.hi() < x.e.lo) return false;
        int c = exact_of(x).compare(exact_of(y));
        return ftb ? c < 0 : c > 0;
      });
      for (std::size_t k = i; k <= j; ++k) sorted[k] = run[k - i].e;
      ++sc.near_tie_runs;
      sc.near_tie_items += j - i + 1;
    }
    *last_chain = i;
    i = j + 1;
  }
  return reach;
}

// Appends the tets of one item: a tet, or a cluster in its local MPVO order for the view.
void ProgressiveOrder::Impl::expand(std::uint32_t item, std::vector<std::uint32_t>& out, Scratch& sc) {
  auto& local_tets = sc.local_tets;
  auto& local_indeg = sc.local_indeg;
  auto& local_queue = sc.local_queue;
  auto& local_edges = sc.local_edges;
  if (!(item & kClusterBit)) {
    out.push_back(item);
    return;
  }
  const SphereTable& t = *table;
  const std::uint32_t k = item & ~kClusterBit;
  const std::uint32_t cb = t.cluster_begin[k], ce = t.cluster_begin[k + 1];
  if (ce - cb <= 64) {
    // Small cells (a grid cube: 5 or 6 tets): predecessor bit masks, planes tested in double with a
    // rounding bound, exact orientation only when in doubt.
    std::uint64_t pred[64] = {};
    std::uint64_t emitted = 0;
    const std::uint32_t size = ce - cb;
    if (!in_subset.empty())
      for (std::uint32_t i = 0; i < size; ++i)
        if (!in_subset[t.cluster_tets[cb + i]]) emitted |= std::uint64_t(1) << i;  // not drawn, no constraints
    const bool persp = view.perspective;
    const double* e = view.eye;
    const double back[3] = {-view.dir[0], -view.dir[1], -view.dir[2]};
    const double en = persp ? std::abs(e[0]) + std::abs(e[1]) + std::abs(e[2])
                            : std::abs(back[0]) + std::abs(back[1]) + std::abs(back[2]);
    for (std::uint32_t f = t.cluster_face_begin[k]; f < t.cluster_face_begin[k + 1]; ++f) {
      const std::uint32_t a = t.face_local[2 * f], b = t.face_local[2 * f + 1];
      const double* pl = t.face_plane.data() + 4 * std::size_t(f);
      double val, bound;
      if (persp) {
        val = pl[0] * e[0] + pl[1] * e[1] + pl[2] * e[2] - pl[3];
        bound = 96 * kEps * double(t.face_scale[f]) * (en + double(t.face_anorm[f]));
      } else {
        val = pl[0] * back[0] + pl[1] * back[1] + pl[2] * back[2];
        bound = 32 * kEps * double(t.face_scale[f]) * en;
      }
      int side = val > bound ? 1 : val < -bound ? -1 : 2;
      if (side == 2) {
        const std::uint32_t* fv = t.face_vertex.data() + 3 * std::size_t(f);
        side = eye_side(view, node(*mesh, fv[0]), node(*mesh, fv[1]), node(*mesh, fv[2]));
      }
      if (side == 0) continue;
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
      out.push_back(t.cluster_tets[cb + pick]);
    }
    return;
  }
  local_tets.clear();
  for (std::uint32_t i = t.cluster_begin[k]; i < t.cluster_begin[k + 1]; ++i)
    if (tet_in(t.cluster_tets[i])) local_tets.push_back(t.cluster_tets[i]);
  if (local_tets.size() == 1) {
    out.push_back(local_tets[0]);
    return;
  }
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
    out.push_back(local_tets[x]);
    for (auto& e : local_edges)
      if (e.first == x && !done[e.second] && --local_indeg[e.second] == 0) local_queue.push_back(e.second);
  }
}

ProgressiveOrder::ProgressiveOrder(const Mesh& mesh, const SphereTable& table, const View& view,
                                   std::span<const std::uint32_t> subset, bool front_to_back)
    : impl_(std::make_unique<Impl>()) {
  impl_->mesh = &mesh;
  impl_->table = &table;
  impl_->view = view;
  impl_->front_to_back = front_to_back;
  impl_->prepare(subset);
}

ProgressiveOrder::~ProgressiveOrder() = default;
ProgressiveOrder::ProgressiveOrder(ProgressiveOrder&&) noexcept = default;
ProgressiveOrder& ProgressiveOrder::operator=(ProgressiveOrder&&) noexcept = default;

std::size_t ProgressiveOrder::Impl::emit_buckets(std::size_t first, std::size_t last, std::size_t limit,
                                                 std::vector<std::uint32_t>& out, Scratch& sc, double* reach_out) {
  const std::size_t nb = limit;
  std::size_t b = first;
  double reach = -std::numeric_limits<double>::infinity();
  while (b < last) {
    std::size_t begin = bucket_begin[b], end = bucket_begin[b + 1];
    ++b;
    if (begin == end) continue;
    sort_bucket(begin, end, sc, b - 1);
    std::size_t chain = begin;
    reach = fix_ties(begin, end, sc, &chain);
    // A near-tie chain may cross into the following buckets: take them in while it does. Bucket b
    // holds no lo below its lower boundary (up to rounding), so most checks need no scan.
    while (b < nb) {
      std::size_t nb_begin = bucket_begin[b], nb_end = bucket_begin[b + 1];
      if (nb_begin == nb_end) {
        ++b;
        continue;
      }
      const double margin = 1e-12 * (std::abs(reach) + std::abs(bucket_min) + 1.0 / bucket_scale);
      if (bucket_scale > 0 && bucket_low(b) > reach + margin) break;
      double next_min = std::min_element(sorted.begin() + nb_begin, sorted.begin() + nb_end)->lo;
      if (next_min > reach) break;
      sort_bucket(nb_begin, nb_end, sc, b);
      end = nb_end;
      ++b;
      reach = fix_ties(chain, end, sc, &chain);
    }
    if (t_cluster_free) {
      for (std::size_t i = begin; i < end; ++i) out.push_back(sorted[i].item);
    } else {
      for (std::size_t i = begin; i < end; ++i) {
        const std::uint32_t item = sorted[i].item;
        if (item & kClusterBit) expand(item, out, sc);
        else out.push_back(item);
      }
    }
  }
  if (reach_out) *reach_out = reach;
  return b;
}

void ProgressiveOrder::Impl::run_worker() {
  const std::size_t nb = bucket_begin.size() - 1;
  std::size_t b = next_bucket;
  bool first = true;
  std::vector<std::uint32_t> pending;
  while (b < nb && !stop) {
    b = emit_buckets(b, b + 1, nb, pending, scratch, nullptr);
    // The first bucket goes out at once; later ones in pendinges of a few thousand tets.
    if (!pending.empty() && (first || pending.size() >= 4096 || b >= nb)) {
      first = false;
      std::lock_guard<std::mutex> g(mu);
      ready.push_back(std::move(pending));
      pending.clear();
      cv.notify_one();
    }
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
  const std::size_t nb = d.bucket_begin.size() - 1;
  if (d.bucket_begin[nb] < 50000) {
    // Small orders: on this thread, bucket by bucket.
    while (d.batch.empty() && d.next_bucket < nb)
      d.next_bucket = d.emit_buckets(d.next_bucket, d.next_bucket + 1, nb, d.batch, d.scratch, nullptr);
    d.add_counts(d.scratch);
  } else {
    if (!d.worker.joinable() && !d.worker_done) d.worker = std::thread([&d] { d.run_worker(); });
    std::unique_lock<std::mutex> lock(d.mu);
    d.cv.wait(lock, [&d] { return !d.ready.empty() || d.worker_done; });
    if (!d.ready.empty()) {
      d.batch.swap(d.ready.front());
      d.ready.pop_front();
    }
    if (d.ready.empty() && d.worker_done) {
      lock.unlock();
      if (d.worker.joinable()) d.worker.join();
      d.add_counts(d.scratch);
    }
  }
  d.handed += d.batch.size();
  return d.batch;
}

std::size_t ProgressiveOrder::handed_out() const { return impl_->handed; }
std::size_t ProgressiveOrder::total() const { return impl_->total_tets; }
const OrderStats& ProgressiveOrder::stats() const { return impl_->stats; }

std::vector<std::uint32_t> visibility_order(const Mesh& mesh, const SphereTable& table, const View& view,
                                            std::span<const std::uint32_t> subset, bool front_to_back,
                                            OrderStats* stats) {
  ProgressiveOrder order(mesh, table, view, subset, front_to_back);
  ProgressiveOrder::Impl& d = *order.impl_;
  const std::size_t nb = d.bucket_begin.size() - 1;
  std::vector<std::uint32_t> out;
  out.reserve(order.total());
  // Both cores: the first half of the buckets here, the second half on another thread. A tie chain
  // across the split (rare) sends everything back through one thread.
  std::size_t split = 0;
  const std::size_t m = d.bucket_begin[nb];
  if (m >= 100000) {
    split = static_cast<std::size_t>(std::lower_bound(d.bucket_begin.begin(), d.bucket_begin.end(),
                                                      static_cast<std::uint32_t>(m / 2)) - d.bucket_begin.begin());
    if (split >= nb) split = 0;
  }
  bool done = false;
  if (split > 0) {
    std::vector<std::uint32_t> second;
    second.reserve(order.total() - order.total() / 2 + 1024);
    ProgressiveOrder::Impl::Scratch other_scratch;
    double reach = 0;
    std::thread other([&] { d.emit_buckets(split, nb, nb, second, other_scratch, nullptr); });
    d.emit_buckets(0, split, split, out, d.scratch, &reach);
    other.join();
    // The first entry of the second half must lie beyond every interval of the first half.
    double second_min = std::numeric_limits<double>::infinity();
    for (std::size_t b = split; b < nb && d.bucket_begin[b] < d.bucket_begin[nb]; ++b) {
      if (d.bucket_begin[b] < d.bucket_begin[b + 1]) {
        second_min = d.sorted[d.bucket_begin[b]].lo;  // sorted by now
        break;
      }
    }
    if (second_min > reach) {
      out.insert(out.end(), second.begin(), second.end());
      d.add_counts(d.scratch);
      d.add_counts(other_scratch);
      done = true;
    } else {
      out.clear();
      d.scratch = {};
    }
  }
  if (!done) {
    d.emit_buckets(0, nb, nb, out, d.scratch, nullptr);
    d.add_counts(d.scratch);
  }
  d.next_bucket = nb;
  d.handed = out.size();
  if (stats) *stats = d.stats;
  return out;
}

std::vector<std::uint32_t> mpvo_order(const Mesh& mesh, const SphereTable& table, const View& view,
                                      std::span<const std::uint32_t> subset, std::size_t* cycles_broken) {
  const std::size_t n = mesh.tet_count();
  std::vector<std::uint32_t> tets;
  if (subset.empty()) {
    tets.resize(n);
    for (std::size_t i = 0; i < n; ++i) tets[i] = static_cast<std::uint32_t>(i);
  } else {
    tets.assign(subset.begin(), subset.end());
  }
  std::vector<std::uint8_t> member(n, 0);
  for (std::uint32_t t : tets) member[t] = 1;
  const double e[3] = {view.eye[0] - table.origin[0], view.eye[1] - table.origin[1], view.eye[2] - table.origin[2]};
  auto key = [&](std::uint32_t t) {
    const double* c = table.c.data() + 3 * std::size_t(t);
    return view.perspective ? table.s[t] - 2 * (c[0] * e[0] + c[1] * e[1] + c[2] * e[2])
                            : c[0] * view.dir[0] + c[1] * view.dir[1] + c[2] * view.dir[2];
  };
  const FaceAdjacency& adj = face_adjacency(mesh);
  // behind[4t+f]: 1 if the neighbour across face f must be drawn before t (it is behind t).
  std::vector<std::uint32_t> indeg(n, 0);
  std::vector<std::uint8_t> edge_out(4 * n, 0);  // 1: t -> neighbour (t drawn first)
  for (std::uint32_t t : tets) {
    const std::uint32_t* v = mesh.tet.data() + 4 * std::size_t(t);
    for (int f = 0; f < 4; ++f) {
      std::uint32_t nb = adj.neighbour[4 * std::size_t(t) + f];
      if (nb == kNone || !member[nb >> 2]) continue;
      std::uint32_t u = nb >> 2;
      if (u < t) continue;
      int side = eye_side(view, node(mesh, v[kFace[f][0]]), node(mesh, v[kFace[f][1]]), node(mesh, v[kFace[f][2]]));
      if (side == 0) continue;
      // t's own vertex is on the negative side: side < 0 means the eye is on t's side (t in front).
      if (side < 0) {
        ++indeg[t];  // u first
        edge_out[(std::size_t(u) << 2) | (nb & 3)] = 1;
      } else {
        ++indeg[u];
        edge_out[4 * std::size_t(t) + f] = 1;
      }
    }
  }
  using Ready = std::pair<double, std::uint32_t>;
  std::priority_queue<Ready> ready;  // largest key (farthest) first
  for (std::uint32_t t : tets)
    if (indeg[t] == 0) ready.emplace(key(t), t);
  // For breaking cycles: all tets by decreasing key.
  std::vector<std::uint32_t> by_key = tets;
  std::sort(by_key.begin(), by_key.end(), [&](std::uint32_t a, std::uint32_t b) { return key(a) > key(b); });
  std::size_t scan = 0, cycles = 0;
  std::vector<std::uint8_t> done(n, 0);
  std::vector<std::uint32_t> out;
  out.reserve(tets.size());
  while (out.size() < tets.size()) {
    if (ready.empty()) {
      while (done[by_key[scan]]) ++scan;
      ready.emplace(key(by_key[scan]), by_key[scan]);
      ++cycles;
    }
    std::uint32_t t = ready.top().second;
    ready.pop();
    if (done[t]) continue;
    done[t] = 1;
    out.push_back(t);
    for (int f = 0; f < 4; ++f) {
      if (!edge_out[4 * std::size_t(t) + f]) continue;
      std::uint32_t u = adj.neighbour[4 * std::size_t(t) + f] >> 2;
      if (!done[u] && indeg[u] > 0 && --indeg[u] == 0) ready.emplace(key(u), u);
    }
  }
  if (cycles_broken) *cycles_broken = cycles;
  return out;
}

std::vector<std::uint32_t> centroid_order(const Mesh& mesh, const View& view, std::span<const std::uint32_t> subset) {
  std::vector<std::uint32_t> tets;
  if (subset.empty()) {
    tets.resize(mesh.tet_count());
    for (std::size_t i = 0; i < tets.size(); ++i) tets[i] = static_cast<std::uint32_t>(i);
  } else {
    tets.assign(subset.begin(), subset.end());
  }
  std::vector<std::pair<double, std::uint32_t>> keyed(tets.size());
  for (std::size_t i = 0; i < tets.size(); ++i) {
    const std::uint32_t* v = mesh.tet.data() + 4 * std::size_t(tets[i]);
    double c[3] = {0, 0, 0};
    for (int k = 0; k < 4; ++k)
      for (int j = 0; j < 3; ++j) c[j] += 0.25 * mesh.xyz[3 * std::size_t(v[k]) + j];
    double d;
    if (view.perspective) {
      d = (c[0] - view.eye[0]) * (c[0] - view.eye[0]) + (c[1] - view.eye[1]) * (c[1] - view.eye[1]) +
          (c[2] - view.eye[2]) * (c[2] - view.eye[2]);
    } else {
      d = c[0] * view.dir[0] + c[1] * view.dir[1] + c[2] * view.dir[2];
    }
    keyed[i] = {d, tets[i]};
  }
  std::sort(keyed.begin(), keyed.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  for (std::size_t i = 0; i < tets.size(); ++i) tets[i] = keyed[i].second;
  return tets;
}

ViolationReport count_violations(const Mesh& mesh, const View& view, std::span<const std::uint32_t> order) {
  const std::size_t n = mesh.tet_count();
  std::vector<std::uint32_t> pos(n, kNone);
  for (std::size_t i = 0; i < order.size(); ++i) pos[order[i]] = static_cast<std::uint32_t>(i);
  const FaceAdjacency& adj = face_adjacency(mesh);
  ViolationReport r;
  std::size_t checked[2] = {0, 0}, wrong[2] = {0, 0};
  parallel_for(order.size(), [&](std::size_t b, std::size_t e, int part) {
    for (std::size_t i = b; i < e; ++i) {
      std::uint32_t t = order[i];
      const std::uint32_t* v = mesh.tet.data() + 4 * std::size_t(t);
      for (int f = 0; f < 4; ++f) {
        std::uint32_t nb = adj.neighbour[4 * std::size_t(t) + f];
        if (nb == kNone) continue;
        std::uint32_t u = nb >> 2;
        if (u < t || pos[u] == kNone) continue;
        int side = eye_side(view, node(mesh, v[kFace[f][0]]), node(mesh, v[kFace[f][1]]), node(mesh, v[kFace[f][2]]));
        if (side == 0) continue;
        ++checked[part];
        // side < 0: the eye is on t's side, t is in front and must come after u.
        bool ok = side < 0 ? pos[u] < pos[t] : pos[t] < pos[u];
        if (!ok) ++wrong[part];
      }
    }
  });
  r.pairs_checked = checked[0] + checked[1];
  r.violations = wrong[0] + wrong[1];
  return r;
}

}  // namespace foxi
