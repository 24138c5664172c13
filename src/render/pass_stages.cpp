#include "render/pass_stages.h"

#include "render/lobe_split.h"
#include "render/next_event.h"

#include "util/parallel.h"

#include "estimator/kernel.h"

#include <algorithm>
#include <cmath>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace pb {

namespace {

// A checkpoint snapshot is written once and read later by another thread: non-temporal stores
// skip reading the destination's cache lines first and leave the cache to the pass's own data.
// PointState is 208 bytes (16-byte multiple) and the vector's storage is 16-byte aligned.
void stream_copy(PointState* dst, const PointState& src) {
#if defined(__SSE2__)
  static_assert(sizeof(PointState) % 16 == 0 && alignof(std::max_align_t) >= 16);
  const __m128i* s = reinterpret_cast<const __m128i*>(&src);
  __m128i* d = reinterpret_cast<__m128i*>(dst);
  for (size_t i = 0; i < sizeof(PointState) / 16; ++i)
    _mm_stream_si128(d + i, _mm_loadu_si128(s + i));
#else
  *dst = src;
#endif
}

void store_fence() {
#if defined(__SSE2__)
  _mm_sfence();
#endif
}

}  // namespace

void build_photon_grid(const std::vector<PhotonHit>& hits, std::span<const float> radii,
                       std::vector<vec3>& positions, HashGrid& grid) {
  positions.resize(hits.size());
  parallel_for(hits.size(), 16384, [&](size_t begin, size_t end) {
    for (size_t k = begin; k < end; ++k) positions[k] = hits[k].position;
  });
  grid.build(positions, radii);
}

namespace {

// The sums of w(t) Phi, w_lap(t) R^2 Phi and w(2 t) Phi (t < 1/2) over a point's photons, the
// nine products and sums in pairs of doubles: (x, y) of each sum, then (z of the first, z of the
// second), then the third's z alone. Each lane computes what the scalar code did, operation
// for operation (kernel.h's polynomials; no contraction on the x86-64 baseline), so the sums
// are the scalar loop's bit for bit. The half-radius weight is the profile at min(2 t, 1),
// exactly 0 from t = 1/2 on (1 + (-10 + 9) in floating point), where the scalar loop added
// nothing; adding 0 Phi changes no sum (the powers are finite and not negative). Issue 40: the
// error estimation's share of a pass, 7.8% with these sums kept one double at a time.
class KernelSums {
 public:
  // Adds a photon at t (0 <= t <= 1) with power `flux`; returns its weight w(t).
  double add(double t, const dvec3& flux) {
    // w(t) and w(2 t) together: the quintic profile at (t, min(2 t, 1)).
    const v2 u = {t, std::min(2.0 * t, 1.0)};
    const v2 u3 = u * u * u;
    const v2 w = 3.5 * (1.0 + u3 * (-10.0 + u * (15.0 - 6.0 * u)));
    // kernel::laplacian_weight_r2, 0 at t = 1 through its (1 - t).
    const double lap = 105.0 * t * (1.0 - t) * (5.0 * t - 3.0);
    const v2 xy = {flux.x, flux.y};
    phi_xy_ += v2{w[0], w[0]} * xy;
    lap_xy_ += v2{lap, lap} * xy;
    half_xy_ += v2{w[1], w[1]} * xy;
    phi_lap_z_ += v2{w[0], lap} * flux.z;
    half_z_ += w[1] * flux.z;
    return w[0];
  }
  void get(dvec3& phi, dvec3& lap, dvec3& half) const {
    phi = {phi_xy_[0], phi_xy_[1], phi_lap_z_[0]};
    lap = {lap_xy_[0], lap_xy_[1], phi_lap_z_[1]};
    half = {half_xy_[0], half_xy_[1], half_z_};
  }

 private:
  using v2 = double __attribute__((vector_size(16)));
  v2 phi_xy_ = {0.0, 0.0}, lap_xy_ = {0.0, 0.0}, half_xy_ = {0.0, 0.0}, phi_lap_z_ = {0.0, 0.0};
  double half_z_ = 0.0;
};

// The kernel sums of one point; photon_flux(h) is what a photon brings before the point's f:
// its power (Lambertian points, whose constant f is multiplied once below) or its power times
// f(wo, wi) (glossy points, whose f holds the path weight alone).
template <bool kLaplacian, class PhotonFlux>
void gather_kernel(const VisiblePoint& point, double r2, const HashGrid& grid,
                   const std::vector<PhotonHit>& hits, PhotonFlux&& photon_flux, PassSums& out,
                   const GuideLearning* learn, const RegionView* region) {
  const float radius = search_radius(r2);
  const double inv_r2 = 1.0 / r2;
  // How far a photon may lie behind or in front of the point's tangent plane (and the point off
  // the photon's) and still count under the rules below: far above the rounding of positions (the
  // point is lifted off its surface by ~1e-7 of its coordinates, so a photon on the same flat
  // surface is "behind" it by that much).
  const vec3 p = point.position;
  const float behind_tol =
      1e-3f * radius + 1e-5f * std::max({std::abs(p.x), std::abs(p.y), std::abs(p.z)});
  // With the Laplacian, the three kernel sums are kept in pairs of doubles (KernelSums): the
  // same products and sums, lane by lane, in half the instructions.
  const bool flat = point.shading == point.normal;
  dvec3 phi(0.0);
  KernelSums sums;
  uint64_t count = 0;
  grid.query(point.position, radius, [&](uint32_t k, float dist2) {
    const PhotonHit& h = hits[k];
    // Same side only (ESTIMATOR.md section 3): the photon must arrive from the half-space the
    // point is seen from, on a surface facing the same way (not the back of a thin wall).
    const float cos_g = glm::dot(h.wi, point.normal);
    if (cos_g <= 0.0f || glm::dot(h.normal, point.normal) <= 0.0f) return;
    // Nor across the point's own surface: a photon behind the point's tangent plane on a
    // surface that faces the point lies on the far side of a sheet the point is on (the inner
    // wall of a thin closed shell, the room under a floor), where no light from it can reach.
    // On one smooth surface the two never hold together (convex: the point is behind the
    // photon's plane; concave: the photon is in front of the point's).
    // Nor from a surface stacked in front of the point's and facing the same way (a board or a
    // ledge in front of a wall, the next tread of a stair): the photon in front of the point's
    // tangent plane and the point behind the photon's. Its light fell on that surface, which
    // may be lit where the point is shaded, and the kernel's mass counts the point's surface
    // alone. On one smooth surface the two never hold together either (concave: the point is
    // in front of the photon's plane; convex: the photon is behind the point's).
    // Both rules: the photon off the point's plane and the point off the photon's, on sides of
    // the same sign. A photon on the point's own plane (most of them) costs one dot product.
    const vec3 d = h.position - p;
    const float ahead_p = glm::dot(d, point.normal);
    if (std::abs(ahead_p) > behind_tol) {
      const float ahead_h = glm::dot(d, h.normal);
      if (std::abs(ahead_h) > behind_tol && (ahead_h > 0.0f) == (ahead_p > 0.0f)) return;
    }
    // Nor beyond the point's edge (ESTIMATOR.md section 11, "The photons of the region"): the
    // kernel's moments count the region of the disc the point's surface reaches, so a photon
    // outside it (on the next of a row of coplanar boards, on a panel beyond a gap) is not the
    // point's: counted, it would be renormalised by a mass that leaves its surface out.
    if (region && !region->contains(d)) return;
    ++count;  // it could contribute, so it counts toward the radius reduction
    // Photon density is flux per area of the true surface; reflected radiance integrates
    // against the shading cosine, hence cos_s / cos_g: exactly 1 where the shading normal is
    // the true one (a flat surface), whose photons skip the dot product and the division.
    dvec3 flux = photon_flux(h);
    if (!flat) {
      const float cos_s = glm::dot(h.wi, point.shading);
      if (cos_s <= 0.0f) return;
      flux *= double(cos_s / cos_g);
    }
    const double t = std::min(1.0, std::sqrt(double(dist2) * inv_r2));
    double w = 0.0;
    if constexpr (kLaplacian) {
      w = sums.add(t, flux);
    } else {
      w = kernel::weight(t);
      phi += w * flux;
    }
    if (learn) learn->chunk->add(h.cell, learn->weight * w * (flux.x + flux.y + flux.z));
  });
  const dvec3 f(point.f);
  if constexpr (kLaplacian) {
    dvec3 lap, half;
    sums.get(phi, lap, half);
    out.phi_lap_r2 += f * lap;
    out.phi_half += f * half;
  }
  out.phi += f * phi;
  out.count += double(count);
}

// Walks a PointBsdfTable alongside the points of its span, in order.
class PointBsdfCursor {
 public:
  PointBsdfCursor(const PointBsdfTable& t, size_t count) : t_(t), end_(t.base + count) {
    it_ = std::lower_bound(t.entries.begin(), t.entries.end(), t.base,
                           [](const PointBsdf& g, size_t i) { return g.point < i; });
  }
  // The entry of point k of the span, or null when that point is Lambertian (k ascending).
  const PointBsdf* at(size_t k) {
    const size_t i = t_.base + k;
    while (it_ != t_.entries.end() && it_->point < i) ++it_;
    return it_ != t_.entries.end() && it_->point == i && i < end_ ? &*it_ : nullptr;
  }

 private:
  PointBsdfTable t_;
  size_t end_;
  std::span<const PointBsdf>::iterator it_;
};

}  // namespace

template <bool kLaplacian>
void gather_photons(const VisiblePoint& point, double r2, const HashGrid& grid,
                    const std::vector<PhotonHit>& hits, PassSums& out, const GuideLearning* learn,
                    const RegionView* region) {
  gather_kernel<kLaplacian>(
      point, r2, grid, hits, [](const PhotonHit& h) { return dvec3(h.flux); }, out, learn, region);
}

template <bool kLaplacian>
void gather_photons(const VisiblePoint& point, const PointBsdf& glossy, double r2,
                    const HashGrid& grid, const std::vector<PhotonHit>& hits, PassSums& out,
                    const GuideLearning* learn, const RegionView* region) {
  gather_kernel<kLaplacian>(
      point, r2, grid, hits,
      [&](const PhotonHit& h) { return dvec3(h.flux * glossy.bsdf.eval(glossy.wo, h.wi)); }, out,
      learn, region);
}

template void gather_photons<true>(const VisiblePoint&, double, const HashGrid&,
                                   const std::vector<PhotonHit>&, PassSums&, const GuideLearning*,
                                   const RegionView*);
template void gather_photons<false>(const VisiblePoint&, double, const HashGrid&,
                                    const std::vector<PhotonHit>&, PassSums&, const GuideLearning*,
                                    const RegionView*);
template void gather_photons<true>(const VisiblePoint&, const PointBsdf&, double, const HashGrid&,
                                   const std::vector<PhotonHit>&, PassSums&, const GuideLearning*,
                                   const RegionView*);
template void gather_photons<false>(const VisiblePoint&, const PointBsdf&, double, const HashGrid&,
                                    const std::vector<PhotonHit>&, PassSums&, const GuideLearning*,
                                    const RegionView*);

void gather_pass(std::span<const VisiblePoint> points, std::span<const PointState> states,
                 const HashGrid& grid, const std::vector<PhotonHit>& hits, PointBsdfTable glossy,
                 const RegionTable* regions, std::span<PassSums> out, GuideTally::Chunk* tally,
                 const GuideInputs& guide) {
  std::fill(out.begin(), out.end(), PassSums{});
  PointBsdfCursor cursor(glossy, points.size());
  RegionTable::Cursor region(regions);
  for (size_t k = 0; k < points.size(); ++k) {
    const VisiblePoint& p = points[k];
    if (!(max_component(p.f) > 0.0f)) continue;  // SPPM: a pixel without a visible point
    GuideLearning learn;
    if (tally) {
      // A photon's share of the point's pass sample X_j is w f Phi / (pi R^2 M_e X); times the
      // point's relative error e / L it is the error the photon stands for (section 14). The
      // constants pi M_e are common to the pass and cancel in the guide's normalisation; the
      // sample X_j is taken as its mean L, the share of e being e / L.
      learn.chunk = tally;
      learn.weight = relative_error(states[k], guide.passes_done, guide.photons_per_pass) *
                     double(p.f.x + p.f.y + p.f.z) / states[k].r2;
    }
    gather_point(p, cursor.at(k), states[k].r2, grid, hits, region.at(uint32_t(k)), out[k],
                 tally ? &learn : nullptr);
  }
}

void gather_point(const VisiblePoint& p, const PointBsdf* glossy, double r2, const HashGrid& grid,
                  const std::vector<PhotonHit>& hits, const RegionView* region, PassSums& out,
                  const GuideLearning* learn) {
  if (glossy)
    gather_photons(p, *glossy, r2, grid, hits, out, learn, region);
  else
    gather_photons(p, r2, grid, hits, out, learn, region);
}

void disc_pass(std::span<const VisiblePoint> points, std::span<const PointState> states,
               const BoundaryIndex* boundary, std::span<const float> clearance,
               std::span<OwnerValues> out, RegionTable& regions) {
  regions.clear();
  DiscRegion region;
  for (size_t k = 0; k < points.size(); ++k) {
    const VisiblePoint& p = points[k];
    if (!(max_component(p.f) > 0.0f)) continue;
    const float r = search_radius(states[k].r2);
    if (!boundary || (!clearance.empty() && r <= clearance[k])) continue;
    if (!boundary->region(p.triangle, p.position, p.normal, r, region)) continue;
    out[k].disc = BoundaryIndex::moments_of(region, r);
    regions.add(uint32_t(k), region);
  }
}

namespace {

// next_event_at up to its shadow rays (direct_light_tests); 0 tests for a point on a GGX lobe's
// diffuse base.
int next_event_tests(const World& world, const VisiblePoint& point, const PointBsdf* glossy,
                     uint64_t seed, uint64_t pass, uint64_t item, ShadowTest* tests) {
  if (glossy && is_base_part(glossy->bsdf)) return 0;  // its camera path counted it
  Rng rng(seed, pass, item, Stream::DirectLight);
  // A glossy point gathered whole (not SPPM's restricted base): its Bsdf's own draws are the
  // environment's other strategy (next_event.h).
  if (glossy && !glossy->bsdf.is_restricted() &&
      environment_mis_applies(world, glossy->bsdf, glossy->bsdf)) {
    const EnvironmentMis mis{&glossy->bsdf, glossy->wo, 1.0f, true};
    return direct_light_tests(world, point, glossy, rng, &mis, tests);
  }
  return direct_light_tests(world, point, glossy, rng, nullptr, tests);
}

}  // namespace

void next_event_pass(const World& world, std::span<const VisiblePoint> points,
                     PointBsdfTable glossy, uint64_t seed, uint64_t pass, size_t first,
                     std::span<OwnerValues> out) {
  // The samples of kGroup points first, then their shadow rays Accel::kPacket at a time (the rays
  // of neighbouring pixels toward one light are coherent: one walk of the BVH serves a packet),
  // then each point's sum: the draws, rays and sums of next_event_at, point by point.
  constexpr size_t kGroup = 64;
  PointBsdfCursor cursor(glossy, points.size());
  ShadowTest tests[kGroup * kMaxShadowTests];
  bool blocked[kGroup * kMaxShadowTests];
  int count[kGroup];
  for (size_t k0 = 0; k0 < points.size(); k0 += kGroup) {
    const size_t m = std::min(kGroup, points.size() - k0);
    size_t n = 0;
    for (size_t i = 0; i < m; ++i) {
      const size_t k = k0 + i;
      count[i] = -1;  // no visible point: nothing added
      if (!(max_component(points[k].f) > 0.0f)) continue;
      count[i] = next_event_tests(world, points[k], cursor.at(k), seed, pass, first + k, tests + n);
      n += size_t(count[i]);
    }
    Accel::Ray rays[Accel::kPacket];
    size_t lane_test[Accel::kPacket];
    int lanes = 0;
    const auto trace = [&] {
      bool b[Accel::kPacket];
      world.accel().occluded_packet(rays, lanes, b);
      for (int l = 0; l < lanes; ++l) blocked[lane_test[l]] = b[l];
      lanes = 0;
    };
    for (size_t t = 0; t < n; ++t) {
      blocked[t] = false;
      if (!tests[t].traced) continue;
      rays[lanes] = tests[t].ray;
      lane_test[lanes++] = t;
      if (lanes == Accel::kPacket) trace();
    }
    if (lanes > 0) trace();
    for (size_t i = 0, t = 0; i < m; ++i) {
      if (count[i] < 0) continue;
      out[k0 + i].direct += shadow_sum(world, tests + t, count[i], blocked + t);
      t += size_t(count[i]);
    }
  }
}

dvec3 next_event_at(const World& world, const VisiblePoint& point, const PointBsdf* glossy,
                    uint64_t seed, uint64_t pass, uint64_t item) {
  ShadowTest tests[kMaxShadowTests];
  const int n = next_event_tests(world, point, glossy, seed, pass, item, tests);
  return shadow_sum(world, tests, n);
}

void fold_pass(std::span<PointState> states, std::span<const PassSums> sums,
               std::span<const OwnerValues> owner, const EstimatorParams& params, uint64_t pass,
               std::span<float> radii, PointState* copy) {
  for (size_t k = 0; k < states.size(); ++k) {
    accumulate_pass(states[k], sums[k], owner[k], params, pass);
    radii[k] = search_radius(states[k].r2);
    if (copy) stream_copy(copy + k, states[k]);
  }
  if (copy) store_fence();  // the streamed stores are visible before the writer reads them
}

bool Share::owns(size_t first_state) const {
  return ranks <= 1 || (first_state / kStageChunk) % size_t(ranks) == size_t(rank);
}

void fold_block(size_t first, std::span<PointState> states, std::span<const PassSums> sums,
                std::span<const OwnerValues> owner, const EstimatorParams& params, uint64_t pass,
                std::span<float> radii, PointState* copy, Share share) {
  for_each_chunk(sums.size(), [&](size_t b, size_t m) {
    if (!share.owns(first + b)) return;
    fold_pass(states.subspan(first + b, m), sums.subspan(b, m), owner.subspan(b, m), params, pass,
              radii.subspan(first + b, m), copy ? copy + first + b : nullptr);
  });
}

}  // namespace pb
