#include "world/accel.h"

#include "scene/texture.h"

#include <embree3/rtcore.h>

#include <cstdio>
#include <limits>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

namespace pb {

namespace {

// Embree reports errors through this callback; we turn them into an exception at the call
// site that checks rtcGetDeviceError, and print the message once here.
void on_embree_error(void*, RTCError code, const char* message) {
  if (code == RTC_ERROR_NONE) return;
  std::fprintf(stderr, "photonbound: embree error %d: %s\n", int(code), message ? message : "");
}

void check(RTCDevice device, const char* what) {
  const RTCError err = rtcGetDeviceError(device);
  if (err != RTC_ERROR_NONE) throw std::runtime_error(std::string("embree failed in ") + what);
}

// What the filter of one alphaMode MASK or BLEND mesh reads.
struct CoveredMesh {
  const Mesh* mesh;
  const Material* material;
  std::span<const Image> images;
};

// Embree's context, extended by the rays' coverage keys, ray id i's at keys[i] (Embree 3
// "rtcInitIntersectContext": an application may append its own data and read it back in its
// filter functions).
struct KeyedContext {
  RTCIntersectContext context;
  const uint64_t* keys;
};

// Embree's filter function for MASK and BLEND meshes, on closest-hit and occlusion rays alike:
// a hit where the alpha is below the cutoff (MASK), or that the ray's key passes (BLEND,
// stops_ray), is rejected, so camera rays, photons and shadow rays all pass the surface the
// same way (Embree 3 "rtcSetGeometryIntersectFilterFunction"; u, v are the hit's barycentrics
// of vertices 1 and 2).
void coverage_filter(const RTCFilterFunctionNArguments* args) {
  const auto* m = static_cast<const CoveredMesh*>(args->geometryUserPtr);
  const uint64_t* keys = reinterpret_cast<const KeyedContext*>(args->context)->keys;
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] != -1) continue;
    const uint64_t key = keys[RTCRayN_id(args->ray, args->N, i)];
    if (m->material->blended() && key == 0) continue;  // met: the caller weighs it
    const unsigned prim = RTCHitN_primID(args->hit, args->N, i);
    const float u = RTCHitN_u(args->hit, args->N, i), v = RTCHitN_v(args->hit, args->N, i);
    const vec2 uv[2] = {mesh_uv(*m->mesh, prim, 0, u, v), mesh_uv(*m->mesh, prim, 1, u, v)};
    const float a = coverage(m->images, *m->material, uv, mesh_alpha(*m->mesh, prim, u, v));
    const unsigned geom = RTCHitN_geomID(args->hit, args->N, i);
    const bool met = m->material->blended() ? stops_ray(key, geom, prim, a) : a > 0.0f;
    if (!met) args->valid[i] = 0;
  }
}

}  // namespace

struct Accel::Impl {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  std::vector<CoveredMesh> covered;  // sized up front: Embree keeps pointers into it
};

Accel::Accel(const Scene& scene) : impl_(std::make_unique<Impl>()) {
  // Embree picks its kernels by the CPU, and its BVH (BVH4 up to AVX, BVH8 from AVX2 on, other
  // kernels with AVX-512) decides every hit's rounding, so the same seed gave other bits on an
  // AVX-512 machine. Capped at AVX2, images are bit-identical on every CPU with AVX2.
  impl_->device = rtcNewDevice("max_isa=avx2");
  if (!impl_->device) throw std::runtime_error("embree: cannot create a device");
  rtcSetDeviceErrorFunction(impl_->device, on_embree_error, nullptr);
  impl_->scene = rtcNewScene(impl_->device);
  rtcSetSceneBuildQuality(impl_->scene, RTC_BUILD_QUALITY_HIGH);
  impl_->covered.reserve(scene.meshes.size());

  for (size_t m = 0; m < scene.meshes.size(); ++m) {
    const Mesh& mesh = scene.meshes[m];
    RTCGeometry geom = rtcNewGeometry(impl_->device, RTC_GEOMETRY_TYPE_TRIANGLE);
    // Embree may read 16 bytes at the last vertex: allocate through Embree, which pads.
    auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0,
                                                          RTC_FORMAT_FLOAT3, sizeof(float) * 3,
                                                          mesh.positions.size()));
    auto* idx = static_cast<uint32_t*>(
        rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                sizeof(uint32_t) * 3, mesh.indices.size() / 3));
    check(impl_->device, "geometry allocation");
    for (size_t i = 0; i < mesh.positions.size(); ++i) {
      v[3 * i + 0] = mesh.positions[i].x;
      v[3 * i + 1] = mesh.positions[i].y;
      v[3 * i + 2] = mesh.positions[i].z;
    }
    std::copy(mesh.indices.begin(), mesh.indices.end(), idx);
    const Material& mat = scene.materials[mesh.material];
    if (mat.masked() || mat.blended()) {
      impl_->covered.push_back({&mesh, &mat, scene.images});
      rtcSetGeometryUserData(geom, &impl_->covered.back());
      rtcSetGeometryIntersectFilterFunction(geom, coverage_filter);
      rtcSetGeometryOccludedFilterFunction(geom, coverage_filter);
    }
    rtcCommitGeometry(geom);
    rtcAttachGeometryByID(impl_->scene, geom, unsigned(m));
    rtcReleaseGeometry(geom);  // the scene holds the reference now
  }
  rtcCommitScene(impl_->scene);
  check(impl_->device, "scene build");
}

Accel::~Accel() {
  if (impl_->scene) rtcReleaseScene(impl_->scene);
  if (impl_->device) rtcReleaseDevice(impl_->device);
}

bool Accel::intersect(const vec3& o, const vec3& d, float tnear, float tfar, Hit& hit,
                      uint64_t key) const {
  KeyedContext context;
  rtcInitIntersectContext(&context.context);
  context.keys = &key;
  RTCRayHit rh;
  rh.ray.org_x = o.x;
  rh.ray.org_y = o.y;
  rh.ray.org_z = o.z;
  rh.ray.dir_x = d.x;
  rh.ray.dir_y = d.y;
  rh.ray.dir_z = d.z;
  rh.ray.tnear = tnear;
  rh.ray.tfar = tfar;
  rh.ray.time = 0.0f;
  rh.ray.mask = 0xffffffffu;
  rh.ray.id = 0;
  rh.ray.flags = 0;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(impl_->scene, &context.context, &rh);
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
  hit.t = rh.ray.tfar;
  hit.mesh = rh.hit.geomID;
  hit.prim = rh.hit.primID;
  hit.u = rh.hit.u;
  hit.v = rh.hit.v;
  return true;
}

namespace {

// Fills packet `r` (RTCRay8 or the ray part of RTCRayHit8) and its valid mask with rays[0, n)
// and their keys; lanes beyond n repeat ray 0 (their results unread), so every lane holds finite
// data.
// A packet's keys and the context its filters read them from.
struct PacketKeys {
  uint64_t keys[Accel::kPacket] = {};
  KeyedContext context;
  PacketKeys() {
    rtcInitIntersectContext(&context.context);
    context.keys = keys;
  }
  PacketKeys(const PacketKeys&) = delete;  // context points into it
};

template <class Ray8>
void fill_packet(const Accel::Ray* rays, int n, Ray8& r, int* valid, uint64_t* keys) {
  for (int i = 0; i < Accel::kPacket; ++i) {
    const Accel::Ray& a = rays[i < n ? i : 0];
    valid[i] = i < n ? -1 : 0;
    keys[i] = a.key;
    r.org_x[i] = a.origin.x;
    r.org_y[i] = a.origin.y;
    r.org_z[i] = a.origin.z;
    r.dir_x[i] = a.dir.x;
    r.dir_y[i] = a.dir.y;
    r.dir_z[i] = a.dir.z;
    r.tnear[i] = a.tnear;
    r.tfar[i] = a.tfar;
    r.time[i] = 0.0f;
    r.mask[i] = 0xffffffffu;
    r.id[i] = unsigned(i);
    r.flags[i] = 0;
  }
}

}  // namespace

void Accel::intersect_packet(const Ray* rays, int n, Hit* hits, bool* found) const {
  static_assert(kPacket == 8, "rtcIntersect8");
  PacketKeys k;
  alignas(32) int valid[kPacket];
  alignas(32) RTCRayHit8 rh;
  fill_packet(rays, n, rh.ray, valid, k.keys);
  for (int i = 0; i < kPacket; ++i) {
    rh.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0][i] = RTC_INVALID_GEOMETRY_ID;
  }
  rtcIntersect8(valid, impl_->scene, &k.context.context, &rh);
  for (int i = 0; i < n; ++i) {
    found[i] = rh.hit.geomID[i] != RTC_INVALID_GEOMETRY_ID;
    if (!found[i]) continue;
    hits[i].t = rh.ray.tfar[i];
    hits[i].mesh = rh.hit.geomID[i];
    hits[i].prim = rh.hit.primID[i];
    hits[i].u = rh.hit.u[i];
    hits[i].v = rh.hit.v[i];
  }
}

void Accel::occluded_packet(const Ray* rays, int n, bool* blocked) const {
  PacketKeys k;
  alignas(32) int valid[kPacket];
  alignas(32) RTCRay8 ray;
  fill_packet(rays, n, ray, valid, k.keys);
  rtcOccluded8(valid, impl_->scene, &k.context.context, &ray);
  // Embree sets tfar to -inf where a ray is occluded.
  for (int i = 0; i < n; ++i) blocked[i] = ray.tfar[i] < 0.0f;
}

bool Accel::occluded(const vec3& o, const vec3& d, float tnear, float tfar, uint64_t key) const {
  KeyedContext context;
  rtcInitIntersectContext(&context.context);
  context.keys = &key;
  RTCRay ray;
  ray.org_x = o.x;
  ray.org_y = o.y;
  ray.org_z = o.z;
  ray.dir_x = d.x;
  ray.dir_y = d.y;
  ray.dir_z = d.z;
  ray.tnear = tnear;
  ray.tfar = tfar;
  ray.time = 0.0f;
  ray.mask = 0xffffffffu;
  ray.id = 0;
  ray.flags = 0;
  rtcOccluded1(impl_->scene, &context.context, &ray);
  // Embree sets tfar to -inf when the ray is occluded.
  return ray.tfar < 0.0f;
}

namespace {

struct SphereQuery {
  Accel::SphereVisit visit;
  void* user;
};

bool on_query_primitive(RTCPointQueryFunctionArguments* args) {
  const SphereQuery* q = static_cast<const SphereQuery*>(args->userPtr);
  q->visit(q->user, args->geomID, args->primID);
  return false;  // the radius is unchanged
}

}  // namespace

void Accel::query_sphere(const vec3& center, float radius, SphereVisit visit, void* user) const {
  RTCPointQuery query;
  query.x = center.x;
  query.y = center.y;
  query.z = center.z;
  query.time = 0.0f;
  query.radius = radius;
  RTCPointQueryContext context;
  rtcInitPointQueryContext(&context);
  SphereQuery q{visit, user};
  rtcPointQuery(impl_->scene, &query, &context, on_query_primitive, &q);
}

}  // namespace pb
