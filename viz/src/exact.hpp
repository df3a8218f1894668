// Internal: the exact arithmetic of the ordering (CGAL), kept in one translation unit because CGAL's
// headers are slow to compile.
#pragma once

#include <cstdint>
#include <memory>

namespace foxi::exact {

// Circumcentre (orthocentre if w is not null: w[0..3] the vertices' weights) of the tet a,b,c,d,
// computed exactly and rounded: c_out = centre, s_out = |c|^2 - r^2. False if the tet is flat.
bool centre(const double* a, const double* b, const double* c, const double* d, const double* w,
            double* c_out, double& s_out);

// Sign of orient3d(a, b, c, p) = sign(det[b-a, c-a, p-a]) (exact).
int orientation(const double* a, const double* b, const double* c, const double* p);

// Sign of ((b-a) x (c-a)) . v (exact): which side of the plane abc a point at infinity along v lies.
int orientation_at_infinity(const double* a, const double* b, const double* c, const double* v);

// For the positively oriented tet a,b,c,d: +1 if q is inside its circumsphere, 0 on it, -1 outside
// (weighted: the power test with weights w[0..3] and wq). Exact.
int in_sphere(const double* a, const double* b, const double* c, const double* d, const double* q,
              const double* w, double wq);

// The exact power key of a tet for a view, for re-comparing near ties. Perspective: the power of the
// eye point w.r.t. the tet's sphere. Orthographic: (c.d, s) compared lexicographically.
class PowerKey {
 public:
  PowerKey();
  ~PowerKey();
  PowerKey(PowerKey&&) noexcept;
  PowerKey& operator=(PowerKey&&) noexcept;
  // Computes the key; w as in centre(). Flat tets get the key of their centroid as a point sphere.
  void set(const double* a, const double* b, const double* c, const double* d, const double* w,
           bool perspective, const double* eye_or_dir);
  // -1, 0, +1 as this key is smaller, equal or larger than `other`.
  int compare(const PowerKey& other) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace foxi::exact
