#include "embree_scene.h"

#include <algorithm>
#include <chrono>
#include <limits>
#include <cstring>
#include <stdexcept>

#include "embree_device.h"

namespace kmbvh {
namespace {

void check(const char* what) {
  if (std::string e = take_embree_error(); !e.empty()) throw std::runtime_error(std::string(what) + ": " + e);
}

Hit from_embree(const RTCRayHit& rh) {
  Hit h;
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return h;
  h.t = rh.ray.tfar;
  h.u = rh.hit.u;
  h.v = rh.hit.v;
  h.Ng = Vec3(rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z);
  h.geomID = rh.hit.geomID;
  h.primID = rh.hit.primID;
  return h;
}

void to_embree(const Ray& r, RTCRay& out) {
  out.org_x = r.org.x;
  out.org_y = r.org.y;
  out.org_z = r.org.z;
  out.dir_x = r.dir.x;
  out.dir_y = r.dir.y;
  out.dir_z = r.dir.z;
  out.tnear = r.tnear;
  out.tfar = r.tfar;
  out.time = 0.0f;
  out.mask = 0xFFFFFFFFu;
  out.id = 0;
  out.flags = 0;
}

void trace_single(RTCScene scene, const Ray& ray, Query query, Hit& hit) {
  hit = Hit();
  if (!ray_is_valid(ray)) return;
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  if (query == Query::Closest) {
    RTCRayHit rh;
    to_embree(ray, rh.ray);
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(scene, &context, &rh);
    hit = from_embree(rh);
  } else {
    RTCRay r;
    to_embree(ray, r);
    rtcOccluded1(scene, &context, &r);
    if (r.tfar == -std::numeric_limits<float>::infinity()) hit.geomID = hit.primID = 0;  // occluded; Embree says not by what
  }
}

// Rays [first, first + n) as one packet of 16 (n <= 16; the rest of the lanes invalid).
void trace_packet(RTCScene scene, const Ray* rays, int n, Query query, Hit* hits) {
  alignas(64) int valid[16];
  alignas(64) RTCRayHit16 rh;
  std::memset(&rh, 0, sizeof(rh));
  for (int i = 0; i < 16; ++i) {
    const bool ok = i < n && ray_is_valid(rays[i]);
    valid[i] = ok ? -1 : 0;
    if (!ok) continue;
    const Ray& r = rays[i];
    rh.ray.org_x[i] = r.org.x, rh.ray.org_y[i] = r.org.y, rh.ray.org_z[i] = r.org.z;
    rh.ray.dir_x[i] = r.dir.x, rh.ray.dir_y[i] = r.dir.y, rh.ray.dir_z[i] = r.dir.z;
    rh.ray.tnear[i] = r.tnear, rh.ray.tfar[i] = r.tfar;
    rh.ray.mask[i] = 0xFFFFFFFFu;
    rh.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0][i] = RTC_INVALID_GEOMETRY_ID;
  }
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  if (query == Query::Closest)
    rtcIntersect16(valid, scene, &context, &rh);
  else
    rtcOccluded16(valid, scene, &context, &rh.ray);
  for (int i = 0; i < n; ++i) {
    Hit& h = hits[i];
    h = Hit();
    if (!valid[i]) continue;
    if (query == Query::Any) {
      if (rh.ray.tfar[i] == -std::numeric_limits<float>::infinity()) h.geomID = h.primID = 0;
      continue;
    }
    if (rh.hit.geomID[i] == RTC_INVALID_GEOMETRY_ID) continue;
    h.t = rh.ray.tfar[i];
    h.u = rh.hit.u[i];
    h.v = rh.hit.v[i];
    h.Ng = Vec3(rh.hit.Ng_x[i], rh.hit.Ng_y[i], rh.hit.Ng_z[i]);
    h.geomID = rh.hit.geomID[i];
    h.primID = rh.hit.primID[i];
  }
}

}  // namespace

EmbreeScene::EmbreeScene(const TriangleScene& scene, RTCBuildQuality quality) {
  RTCDevice device = shared_embree_device();
  scene_ = rtcNewScene(device);
  check("rtcNewScene");
  rtcSetSceneBuildQuality(scene_, quality);
  const auto start = std::chrono::steady_clock::now();
  if (!scene.triangles.empty()) {
    RTCGeometry geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* vertices = static_cast<float*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                                  3 * sizeof(float), scene.positions.size()));
    auto* indices = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                                    3 * sizeof(uint32_t), scene.triangles.size()));
    check("rtcSetNewGeometryBuffer");
    std::memcpy(vertices, scene.positions.data(), scene.positions.size() * sizeof(Vec3));
    std::memcpy(indices, scene.triangles.data(), scene.triangles.size() * sizeof(Triangle));
    rtcSetGeometryBuildQuality(geometry, quality);
    rtcCommitGeometry(geometry);
    rtcAttachGeometryByID(scene_, geometry, 0);
    rtcReleaseGeometry(geometry);
  }
  rtcCommitScene(scene_);
  commit_ms_ = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  check("rtcCommitScene");
}

EmbreeScene::~EmbreeScene() {
  if (scene_) rtcReleaseScene(scene_);
}

void EmbreeScene::trace_one(const Ray& ray, Query query, Hit& hit) const { trace_single(scene_, ray, query, hit); }

void EmbreeScene::trace(const std::vector<Ray>& rays, Query query, EmbreeRays form, std::vector<Hit>& hits) const {
  hits.resize(rays.size());
  trace(rays.data(), rays.size(), query, form, hits.data());
}

void EmbreeScene::trace(const Ray* rays, size_t count, Query query, EmbreeRays form, Hit* hits) const {
  const long n = long(count);
  if (form == EmbreeRays::Single) {
#pragma omp parallel for schedule(dynamic, 256)
    for (long i = 0; i < n; ++i) trace_single(scene_, rays[size_t(i)], query, hits[size_t(i)]);
  } else {
#pragma omp parallel for schedule(dynamic, 16)
    for (long p = 0; p < (n + 15) / 16; ++p)
      trace_packet(scene_, rays + p * 16, int(std::min<long>(16, n - p * 16)), query, hits + p * 16);
  }
}

}  // namespace kmbvh
