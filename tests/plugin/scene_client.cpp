// An Embree application for the preload library's scene path (tests/plugin/CMakeLists.txt):
// it builds a scene with Embree's own API (three triangle meshes, each handed over a
// different way: a shared buffer with an offset and a padded stride, a buffer Embree
// allocates and the client fills afterwards, an RTCBuffer with an offset), traces the
// same rays with every query form Embree has (rtcIntersect1/4/8/16, 1M, 1Mp, NM, Np and
// the occluded ones), and dumps the answers. Run once on Embree and once under
// LD_PRELOAD; `compare` then checks that both answered alike, and that under kmbvh every
// form gave exactly what rtcIntersect1 gave.
//
//   scene_client trace SCENE OUT.bin [--filter] [--quad]   (SCENE: a file, or "default")
//   scene_client compare SCENE REFERENCE.bin TEST.bin [--filter] [--exact-forms]
//   scene_client time SCENE RUNS   (scripts/bench_packets_preload.sh)
//
// `time` prints the Mrays/s of rtcIntersect1 and rtcIntersect16 on the scene's primary
// rays, and of rtcOccluded1 and rtcOccluded16 on its shadow rays (100,000 of each, one
// thread, the median of RUNS runs): run alone and under the preload, the same calls
// measure Embree and kmbvh.
// --filter: mesh 1 gets intersect and occluded filter functions that refuse odd primIDs.
// --quad:   an enabled quad mesh is attached too, which kmbvh does not answer (fallback).
// --dynamic: the scene is RTC_SCENE_FLAG_DYNAMIC and, once committed, every vertex is moved
//           (rtcUpdateGeometryBuffer, rtcCommitGeometry) and the scene committed again, as
//           an animation does: kmbvh refits its tree instead of building it again.
// --scatter: as --dynamic, with the scene's parts also thrown pseudo-random distances, so
//           the refitted trees are far worse than new ones and kmbvh builds them again.
// --refit-quality: every mesh asks for refits (RTC_BUILD_QUALITY_REFIT), which Embree and
//           kmbvh then refit however the motion spoils them.
// --low:    the scene asks for RTC_BUILD_QUALITY_LOW, as Embree's dynamic_scene tutorial does
//           (kmbvh then builds with LBVH: plugin/README.md, "Build quality").
// --recommit: a static scene's vertices moved as --dynamic moves them and the scene
//           committed again, twice: kmbvh builds it three times, the first without keeping
//           its build memory, the later ones in the memory the second kept.
#include <embree3/rtcore.h>
#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "adapters/in/default_scene.h"
#include "adapters/in/load_scene.h"
#include "adapters/rays/hit_compare.h"
#include "adapters/rays/scene_rays.h"

using namespace kmbvh;

namespace {

constexpr int kMeshes = 3;
constexpr uint32_t kSeed = 7;
constexpr size_t kRaysPerKind = 20000;

// What one query answered, as the application sees it.
struct Answer {
  float tfar, Ng_x, Ng_y, Ng_z, u, v;
  uint32_t geomID, primID, instID;
  bool operator==(const Answer& o) const { return std::memcmp(this, &o, sizeof(Answer)) == 0; }
};

const char* const kForms[] = {"1", "4", "8", "16", "1M", "1Mp", "NM", "Np"};
constexpr int kFormCount = 8;

struct Options {
  std::string scene;
  bool filter = false, quad = false, exact_forms = false, dynamic = false, scatter = false, refit_quality = false,
       low = false, recommit = false;
  bool moves() const { return dynamic || recommit; }  // the vertices move after the first commit
};

// Where --dynamic moves a vertex: the scene grown by 1%, shifted along x and rippled in y,
// so every box of the first commit's tree is wrong after it and the triangles change shape.
// With --scatter, the scene is cut into cells of an eighth of that size, and each cell's
// vertices then go a pseudo-random distance of up to half the size along each axis: the
// triangles within a cell move together, the first tree's clusters are torn apart.
Vec3 moved(Vec3 p, const Aabb& bounds, bool scatter) {
  const Vec3 e = bounds.extent();
  const float size = std::max(e.x, std::max(e.y, e.z));
  const Vec3 q = p * 1.01f + Vec3(0.02f * size, 0.01f * size * std::sin(6.0f * (p.x - bounds.lo.x) / size), 0.0f);
  if (!scatter) return q;
  uint32_t h = 0;
  for (int d = 0; d < 3; ++d) h = (h + uint32_t(std::floor(8.0f * (p[d] - bounds.lo[d]) / size))) * 2654435761u;
  const auto throw_by = [&](int shift) { return (float((h >> shift) & 255u) / 255.0f - 0.5f) * size; };
  return q + Vec3(throw_by(0), throw_by(8), throw_by(16));
}

TriangleScene moved(TriangleScene scene, bool scatter) {
  const Aabb bounds = scene.bounds();
  for (Vec3& p : scene.positions) p = moved(p, bounds, scatter);
  return scene;
}

TriangleScene load(const std::string& name) {
  return name == "default" ? make_default_scene() : load_scene_file(name);
}

// Mesh m holds triangles [first(m), first(m + 1)) of the scene.
size_t first(const TriangleScene& scene, int m) { return scene.triangles.size() * size_t(m) / kMeshes; }

bool refused(uint32_t geomID, uint32_t primID) { return geomID == 1 && primID % 2 == 1; }

std::atomic<uint64_t> filter_calls{0}, bad_user_data{0};
int user_data_tag;

void refuse_odd(const RTCFilterFunctionNArguments* args) {
  ++filter_calls;
  if (args->geometryUserPtr != &user_data_tag) ++bad_user_data;
  for (unsigned i = 0; i < args->N; ++i)
    if (args->valid[i] == -1 && refused(RTCHitN_geomID(args->hit, args->N, i), RTCHitN_primID(args->hit, args->N, i)))
      args->valid[i] = 0;
}

std::vector<Ray> all_rays(const TriangleScene& scene, std::vector<unsigned>& masks) {
  const RaySets sets = scene_ray_sets(scene, make_primitive_set(scene), kRaysPerKind, kSeed);
  std::vector<Ray> rays;
  for (RayKind k : {RayKind::Primary, RayKind::Shadow, RayKind::Diffuse})
    rays.insert(rays.end(), sets.of(k).begin(), sets.of(k).end());
  masks.assign(rays.size(), 0xFFFFFFFFu);
  for (size_t i = 0; i < rays.size(); i += 97) masks[i] = 0;  // a ray of mask 0 hits nothing
  return rays;
}

RTCScene build_scene(RTCDevice device, const TriangleScene& scene, const Options& o, std::vector<std::vector<char>>& keep) {
  RTCScene s = rtcNewScene(device);
  if (o.dynamic) rtcSetSceneFlags(s, RTC_SCENE_FLAG_DYNAMIC);
  if (o.low) rtcSetSceneBuildQuality(s, RTC_BUILD_QUALITY_LOW);
  const size_t nv = scene.positions.size();
  float* vertices[kMeshes] = {};  // each mesh's vertex x, y, z, at its stride
  size_t stride[kMeshes] = {};
  for (int m = 0; m < kMeshes; ++m) {
    const size_t lo = first(scene, m), n = first(scene, m + 1) - lo;
    RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    if (m == 0) {  // shared: 4 bytes of padding before each vertex, 16-byte stride
      keep.emplace_back(nv * 16 + 16);
      char* v = keep.back().data();
      for (size_t i = 0; i < nv; ++i) std::memcpy(v + 16 * i + 4, &scene.positions[i], 12);
      rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, v, 4, 16, nv);
      vertices[m] = reinterpret_cast<float*>(v + 4), stride[m] = 16;
      keep.emplace_back(n * 12 + 4);
      std::memcpy(keep.back().data(), &scene.triangles[lo], n * 12);
      rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, keep.back().data(), 0, 12, n);
    } else if (m == 1) {  // Embree's memory, filled after the call
      auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 12, nv));
      auto* t = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 12, n));
      std::memcpy(v, scene.positions.data(), nv * 12);
      std::memcpy(t, &scene.triangles[lo], n * 12);
      vertices[m] = v, stride[m] = 12;
      if (o.filter) {
        rtcSetGeometryUserData(g, &user_data_tag);
        rtcSetGeometryIntersectFilterFunction(g, refuse_odd);
        rtcSetGeometryOccludedFilterFunction(g, refuse_odd);
      }
    } else {  // an RTCBuffer: vertices after 32 bytes, indices padded to 16 bytes
      RTCBuffer vb = rtcNewBuffer(device, 32 + nv * 12 + 4);
      std::memcpy(static_cast<char*>(rtcGetBufferData(vb)) + 32, scene.positions.data(), nv * 12);
      rtcSetGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, vb, 32, 12, nv);
      vertices[m] = reinterpret_cast<float*>(static_cast<char*>(rtcGetBufferData(vb)) + 32), stride[m] = 12;
      RTCBuffer ib = rtcNewBuffer(device, n * 16 + 16);
      for (size_t i = 0; i < n; ++i)
        std::memcpy(static_cast<char*>(rtcGetBufferData(ib)) + 16 * i, &scene.triangles[lo + i], 12);
      rtcSetGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, ib, 0, 16, n);
      rtcReleaseBuffer(vb);
      rtcReleaseBuffer(ib);
    }
    if (o.refit_quality) rtcSetGeometryBuildQuality(g, RTC_BUILD_QUALITY_REFIT);
    rtcCommitGeometry(g);
    rtcAttachGeometry(s, g);
    rtcReleaseGeometry(g);
  }
  // A quad far below the scene: disabled, it changes nothing; enabled (--quad), kmbvh
  // leaves the scene to Embree.
  RTCGeometry q = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_QUAD);
  const Aabb b = scene.bounds();
  const float y = b.lo.y - 1000.0f;
  auto* qv = static_cast<float*>(rtcSetNewGeometryBuffer(q, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 12, 4));
  const float quad[12] = {-1, y, -1, 1, y, -1, 1, y, 1, -1, y, 1};
  std::memcpy(qv, quad, sizeof(quad));
  auto* qi = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(q, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT4, 16, 1));
  for (uint32_t i = 0; i < 4; ++i) qi[i] = i;
  rtcCommitGeometry(q);
  if (!o.quad) rtcDisableGeometry(q);
  rtcAttachGeometry(s, q);
  rtcReleaseGeometry(q);
  rtcCommitScene(s);
  // The next frame of an animation (--dynamic): every vertex moved, the triangles the same;
  // with --recommit, a static scene changed so, committed again, and once more.
  for (int again = 0; again < (o.recommit ? 2 : o.dynamic ? 1 : 0); ++again) {
    const Aabb bounds = scene.bounds();
    for (unsigned m = 0; m < unsigned(kMeshes); ++m) {
      for (size_t i = 0; i < nv; ++i) {
        float* p = reinterpret_cast<float*>(reinterpret_cast<char*>(vertices[m]) + stride[m] * i);
        const Vec3 to = moved(scene.positions[i], bounds, o.scatter);
        p[0] = to.x, p[1] = to.y, p[2] = to.z;
      }
      RTCGeometry g = rtcGetGeometry(s, m);
      rtcUpdateGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0);
      rtcCommitGeometry(g);
    }
    rtcCommitScene(s);
  }
  return s;
}

template <typename R>
void put_ray(R& r, size_t lane, const Ray& ray, unsigned mask) {
  r.org_x[lane] = ray.org.x, r.org_y[lane] = ray.org.y, r.org_z[lane] = ray.org.z, r.tnear[lane] = ray.tnear;
  r.dir_x[lane] = ray.dir.x, r.dir_y[lane] = ray.dir.y, r.dir_z[lane] = ray.dir.z, r.time[lane] = 0.0f;
  r.tfar[lane] = ray.tfar, r.mask[lane] = mask, r.id[lane] = unsigned(lane), r.flags[lane] = 0;
}

void put_ray(RTCRay& r, const Ray& ray, unsigned mask) {
  r.org_x = ray.org.x, r.org_y = ray.org.y, r.org_z = ray.org.z, r.tnear = ray.tnear;
  r.dir_x = ray.dir.x, r.dir_y = ray.dir.y, r.dir_z = ray.dir.z, r.time = 0.0f;
  r.tfar = ray.tfar, r.mask = mask, r.id = 0, r.flags = 0;
}

constexpr uint32_t kUntouched = 0xABCDu;  // what hit fields hold until a hit is written

void clear_hit(RTCHit& h) {
  h.Ng_x = h.Ng_y = h.Ng_z = h.u = h.v = -1.0f;
  h.geomID = RTC_INVALID_GEOMETRY_ID, h.primID = kUntouched, h.instID[0] = kUntouched;
}

Answer answer(const RTCRayHit& rh) {
  return Answer{rh.ray.tfar, rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z, rh.hit.u, rh.hit.v, rh.hit.geomID, rh.hit.primID, rh.hit.instID[0]};
}

// Packets of K in SoA form: lane i of packet p is ray K * p + i; the last packet's spare
// lanes are invalid (and must be left alone).
template <int K, typename RayHitK, typename RayK, typename Intersect, typename Occlude>
void trace_packets(RTCScene s, RTCIntersectContext* c, const std::vector<Ray>& rays, const std::vector<unsigned>& masks,
                   Intersect intersect, Occlude occlude, std::vector<Answer>& closest, std::vector<Answer>& any) {
  for (size_t p = 0; p * K < rays.size(); ++p) {
    alignas(64) int valid[K];
    alignas(64) RayHitK rh;
    alignas(64) RayK r;
    for (int i = 0; i < K; ++i) {
      const size_t at = p * K + i;
      valid[i] = at < rays.size() ? -1 : 0;
      const Ray ray = at < rays.size() ? rays[at] : Ray{};
      put_ray(rh.ray, i, ray, at < rays.size() ? masks[at] : 0);
      put_ray(r, i, ray, at < rays.size() ? masks[at] : 0);
      rh.hit.Ng_x[i] = rh.hit.Ng_y[i] = rh.hit.Ng_z[i] = rh.hit.u[i] = rh.hit.v[i] = -1.0f;
      rh.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID, rh.hit.primID[i] = kUntouched, rh.hit.instID[0][i] = kUntouched;
    }
    intersect(valid, s, c, &rh);
    occlude(valid, s, c, &r);
    for (int i = 0; i < K; ++i) {
      const size_t at = p * K + i;
      if (at >= rays.size()) {
        if (rh.hit.primID[i] != kUntouched || r.tfar[i] != Ray{}.tfar) throw std::runtime_error("an invalid lane was written");
        continue;
      }
      closest[at] = Answer{rh.ray.tfar[i], rh.hit.Ng_x[i], rh.hit.Ng_y[i], rh.hit.Ng_z[i], rh.hit.u[i], rh.hit.v[i],
                           rh.hit.geomID[i], rh.hit.primID[i], rh.hit.instID[0][i]};
      any[at] = Answer{r.tfar[i], 0, 0, 0, 0, 0, 0, 0, 0};
    }
  }
}

// answers[form][0]: closest hits, [1]: occlusion, one Answer per ray.
using Answers = std::vector<std::vector<Answer>>;

Answers trace_all_forms(RTCScene s, const std::vector<Ray>& rays, const std::vector<unsigned>& masks) {
  const size_t n = rays.size();
  Answers out(2 * kFormCount, std::vector<Answer>(n));
  RTCIntersectContext c;
  rtcInitIntersectContext(&c);
  std::vector<RTCRayHit> rh(n);
  std::vector<RTCRay> r(n);
  const auto reset = [&] {
    for (size_t i = 0; i < n; ++i) {
      put_ray(rh[i].ray, rays[i], masks[i]);
      clear_hit(rh[i].hit);
      put_ray(r[i], rays[i], masks[i]);
    }
  };
  const auto collect = [&](int form) {
    for (size_t i = 0; i < n; ++i) {
      out[2 * form][i] = answer(rh[i]);
      out[2 * form + 1][i] = Answer{r[i].tfar, 0, 0, 0, 0, 0, 0, 0, 0};
    }
  };
  // 1
  reset();
  for (size_t i = 0; i < n; ++i) rtcIntersect1(s, &c, &rh[i]), rtcOccluded1(s, &c, &r[i]);
  collect(0);
  // 4, 8, 16
  trace_packets<4, RTCRayHit4, RTCRay4>(s, &c, rays, masks, rtcIntersect4, rtcOccluded4, out[2], out[3]);
  trace_packets<8, RTCRayHit8, RTCRay8>(s, &c, rays, masks, rtcIntersect8, rtcOccluded8, out[4], out[5]);
  trace_packets<16, RTCRayHit16, RTCRay16>(s, &c, rays, masks, rtcIntersect16, rtcOccluded16, out[6], out[7]);
  // 1M: streams of 64 rays, stride of one RTCRayHit
  reset();
  for (size_t i = 0; i < n; i += 64) {
    const unsigned m = unsigned(std::min<size_t>(64, n - i));
    rtcIntersect1M(s, &c, &rh[i], m, sizeof(RTCRayHit));
    rtcOccluded1M(s, &c, &r[i], m, sizeof(RTCRay));
  }
  collect(4);
  // 1Mp: pointers to the rays
  reset();
  std::vector<RTCRayHit*> rhp(n);
  std::vector<RTCRay*> rp(n);
  for (size_t i = 0; i < n; ++i) rhp[i] = &rh[i], rp[i] = &r[i];
  for (size_t i = 0; i < n; i += 64) {
    const unsigned m = unsigned(std::min<size_t>(64, n - i));
    rtcIntersect1Mp(s, &c, &rhp[i], m);
    rtcOccluded1Mp(s, &c, &rp[i], m);
  }
  collect(5);
  // NM: packets of 8 in RTCRayHitN layout (an RTCRayHit8 is one), every lane active
  {
    const size_t packets = (n + 7) / 8;
    std::vector<RTCRayHit8> prh(packets);
    std::vector<RTCRay8> pr(packets);
    for (size_t i = 0; i < packets * 8; ++i) {
      const Ray ray = i < n ? rays[i] : Ray{};
      const unsigned mask = i < n ? masks[i] : 0;
      put_ray(prh[i / 8].ray, i % 8, ray, mask);
      put_ray(pr[i / 8], i % 8, ray, mask);
      RTCHit8& h = prh[i / 8].hit;
      h.Ng_x[i % 8] = h.Ng_y[i % 8] = h.Ng_z[i % 8] = h.u[i % 8] = h.v[i % 8] = -1.0f;
      h.geomID[i % 8] = RTC_INVALID_GEOMETRY_ID, h.primID[i % 8] = kUntouched, h.instID[0][i % 8] = kUntouched;
    }
    rtcIntersectNM(s, &c, reinterpret_cast<RTCRayHitN*>(prh.data()), 8, unsigned(packets), sizeof(RTCRayHit8));
    rtcOccludedNM(s, &c, reinterpret_cast<RTCRayN*>(pr.data()), 8, unsigned(packets), sizeof(RTCRay8));
    for (size_t i = 0; i < n; ++i) {
      const RTCRayHit8& p = prh[i / 8];
      const size_t l = i % 8;
      out[12][i] = Answer{p.ray.tfar[l], p.hit.Ng_x[l], p.hit.Ng_y[l], p.hit.Ng_z[l], p.hit.u[l], p.hit.v[l],
                          p.hit.geomID[l], p.hit.primID[l], p.hit.instID[0][l]};
      out[13][i] = Answer{pr[i / 8].tfar[l], 0, 0, 0, 0, 0, 0, 0, 0};
    }
  }
  // Np: every field its own array
  {
    std::vector<float> f[18];
    std::vector<unsigned> u[9];
    for (auto& v : f) v.resize(n);
    for (auto& v : u) v.resize(n);
    RTCRayHitNp np;
    RTCRayNp onp;
    float** fields[] = {&np.ray.org_x, &np.ray.org_y, &np.ray.org_z, &np.ray.tnear, &np.ray.dir_x, &np.ray.dir_y,
                        &np.ray.dir_z, &np.ray.time, &np.ray.tfar, &np.hit.Ng_x, &np.hit.Ng_y, &np.hit.Ng_z,
                        &np.hit.u, &np.hit.v, &onp.tfar};
    for (int k = 0; k < 15; ++k) *fields[k] = f[k].data();
    unsigned** ufields[] = {&np.ray.mask, &np.ray.id, &np.ray.flags, &np.hit.primID, &np.hit.geomID, &np.hit.instID[0]};
    for (int k = 0; k < 6; ++k) *ufields[k] = u[k].data();
    onp.org_x = np.ray.org_x, onp.org_y = np.ray.org_y, onp.org_z = np.ray.org_z, onp.tnear = np.ray.tnear;
    onp.dir_x = np.ray.dir_x, onp.dir_y = np.ray.dir_y, onp.dir_z = np.ray.dir_z, onp.time = np.ray.time;
    onp.mask = np.ray.mask, onp.id = np.ray.id, onp.flags = np.ray.flags;
    for (size_t i = 0; i < n; ++i) {
      const Ray& ray = rays[i];
      f[0][i] = ray.org.x, f[1][i] = ray.org.y, f[2][i] = ray.org.z, f[3][i] = ray.tnear;
      f[4][i] = ray.dir.x, f[5][i] = ray.dir.y, f[6][i] = ray.dir.z, f[7][i] = 0.0f, f[8][i] = ray.tfar;
      for (int k = 9; k < 14; ++k) f[k][i] = -1.0f;
      f[14][i] = ray.tfar;
      u[0][i] = masks[i], u[1][i] = 0, u[2][i] = 0, u[3][i] = kUntouched, u[4][i] = RTC_INVALID_GEOMETRY_ID, u[5][i] = kUntouched;
    }
    rtcIntersectNp(s, &c, &np, unsigned(n));
    rtcOccludedNp(s, &c, &onp, unsigned(n));
    for (size_t i = 0; i < n; ++i) {
      out[14][i] = Answer{f[8][i], f[9][i], f[10][i], f[11][i], f[12][i], f[13][i], u[4][i], u[3][i], u[5][i]};
      out[15][i] = Answer{f[14][i], 0, 0, 0, 0, 0, 0, 0, 0};
    }
  }
  return out;
}

void write_dump(const std::string& path, const std::vector<Ray>& rays, const Answers& answers) {
  std::ofstream f(path, std::ios::binary);
  const uint64_t n = rays.size();
  f.write(reinterpret_cast<const char*>(&n), sizeof(n));
  f.write(reinterpret_cast<const char*>(rays.data()), std::streamsize(n * sizeof(Ray)));
  for (const auto& a : answers) f.write(reinterpret_cast<const char*>(a.data()), std::streamsize(n * sizeof(Answer)));
  if (!f) throw std::runtime_error("cannot write " + path);
}

void read_dump(const std::string& path, std::vector<Ray>& rays, Answers& answers) {
  std::ifstream f(path, std::ios::binary);
  uint64_t n = 0;
  f.read(reinterpret_cast<char*>(&n), sizeof(n));
  if (!f || n > (uint64_t(1) << 26)) throw std::runtime_error("cannot read " + path);
  rays.resize(n);
  f.read(reinterpret_cast<char*>(rays.data()), std::streamsize(n * sizeof(Ray)));
  answers.assign(2 * kFormCount, std::vector<Answer>(n));
  for (auto& a : answers) f.read(reinterpret_cast<char*>(a.data()), std::streamsize(n * sizeof(Answer)));
  if (!f) throw std::runtime_error("truncated " + path);
}

int trace(const Options& o, const std::string& out) {
  const TriangleScene scene = load(o.scene);
  std::vector<unsigned> masks;
  const std::vector<Ray> rays = all_rays(o.moves() ? moved(scene, o.scatter) : scene, masks);
  RTCDevice device = rtcNewDevice(nullptr);
  std::vector<std::vector<char>> keep;
  RTCScene s = build_scene(device, scene, o, keep);
  const Answers answers = trace_all_forms(s, rays, masks);
  rtcReleaseScene(s);
  rtcReleaseDevice(device);
  write_dump(out, rays, answers);
  if (bad_user_data) return std::fprintf(stderr, "a filter function got the wrong user data\n"), 1;
  if (o.filter && filter_calls == 0) return std::fprintf(stderr, "the filter functions were never called\n"), 1;
  std::printf("%zu rays, %d forms, %llu filter calls\n", rays.size(), kFormCount, (unsigned long long)filter_calls.load());
  return 0;
}

// The median seconds of `runs` calls of `f`, each after `prepare` (untimed).
template <typename Prepare, typename F>
double median_seconds(int runs, const Prepare& prepare, const F& f) {
  std::vector<double> t;
  for (int i = 0; i < runs; ++i) {
    prepare();
    const auto start = std::chrono::steady_clock::now();
    f();
    t.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  std::sort(t.begin(), t.end());
  return t[t.size() / 2];
}

int time_forms(const Options& o, int runs) {
  const TriangleScene scene = load(o.scene);
  const RaySets sets = scene_ray_sets(scene, make_primitive_set(scene), 100000, kSeed);
  RTCDevice device = rtcNewDevice(nullptr);
  std::vector<std::vector<char>> keep;
  RTCScene s = build_scene(device, scene, o, keep);
  RTCIntersectContext c;
  rtcInitIntersectContext(&c);
  for (const RayKind kind : {RayKind::Primary, RayKind::Shadow}) {
    const std::vector<Ray>& rays = sets.of(kind);
    const size_t n = rays.size(), packets = (n + 15) / 16;
    std::vector<RTCRayHit> single(n), single_in(n);
    for (size_t i = 0; i < n; ++i) put_ray(single_in[i].ray, rays[i], ~0u), clear_hit(single_in[i].hit);
    std::vector<RTCRayHit16> packet(packets), packet_in(packets);
    struct alignas(64) Valid16 {  // Embree reads a packet's valid mask as one aligned vector
      int lane[16];
    };
    std::vector<Valid16> valid(packets);
    for (size_t p = 0; p < packets; ++p)
      for (size_t i = 0; i < 16; ++i) {
        const size_t at = p * 16 + i;
        valid[p].lane[i] = at < n ? -1 : 0;
        put_ray(packet_in[p].ray, i, at < n ? rays[at] : Ray{}, ~0u);
        packet_in[p].hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
      }
    const bool shadow = kind == RayKind::Shadow;
    const double one = median_seconds(runs, [&] { single = single_in; }, [&] {
      for (size_t i = 0; i < n; ++i) shadow ? rtcOccluded1(s, &c, &single[i].ray) : rtcIntersect1(s, &c, &single[i]);
    });
    const double sixteen = median_seconds(runs, [&] { packet = packet_in; }, [&] {
      for (size_t p = 0; p < packets; ++p)
        shadow ? rtcOccluded16(valid[p].lane, s, &c, &packet[p].ray) : rtcIntersect16(valid[p].lane, s, &c, &packet[p]);
    });
    std::printf("%s %zu rays: %s1 %.2f Mrays/s, %s16 %.2f Mrays/s\n", to_string(kind), n,
                shadow ? "rtcOccluded" : "rtcIntersect", n / one * 1e-6, shadow ? "rtcOccluded" : "rtcIntersect",
                n / sixteen * 1e-6);
  }
  rtcReleaseScene(s);
  rtcReleaseDevice(device);
  return 0;
}

// The scene the answers can be checked against: the triangles a hit may land on (with
// --filter, the refused ones are left out), indexed by (geomID, primID).
struct CheckScene {
  TriangleScene scene;
  std::map<std::pair<uint32_t, uint32_t>, uint32_t> index;
};

CheckScene check_scene(const TriangleScene& full, bool filter) {
  CheckScene c;
  c.scene.positions = full.positions;
  for (int m = 0; m < kMeshes; ++m)
    for (size_t t = first(full, m); t < first(full, m + 1); ++t) {
      const auto prim = uint32_t(t - first(full, m));
      if (filter && refused(uint32_t(m), prim)) continue;
      c.index[{uint32_t(m), prim}] = uint32_t(c.scene.triangles.size());
      c.scene.triangles.push_back(full.triangles[t]);
    }
  return c;
}

// How far n is from the triangle's exact cross(b - a, c - a), relative to its size.
double normal_error(const TriangleScene& scene, uint32_t prim, Vec3 n) {
  const Triangle& t = scene.triangles[prim];
  const Vec3 a = scene.positions[t[0]], b = scene.positions[t[1]], c = scene.positions[t[2]];
  const double e1[3] = {double(b.x) - a.x, double(b.y) - a.y, double(b.z) - a.z};
  const double e2[3] = {double(c.x) - a.x, double(c.y) - a.y, double(c.z) - a.z};
  const double x[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
  const double scale = std::max({std::fabs(x[0]), std::fabs(x[1]), std::fabs(x[2])});
  return std::max({std::fabs(n.x - x[0]), std::fabs(n.y - x[1]), std::fabs(n.z - x[2])}) / std::max(scale, 1e-300);
}

Hit as_hit(const Answer& a, Query query, const CheckScene& c) {
  Hit h;
  if (query == Query::Any) {
    if (a.tfar == -std::numeric_limits<float>::infinity()) h.geomID = h.primID = 0;
    return h;
  }
  if (a.geomID == RTC_INVALID_GEOMETRY_ID) return h;
  h.t = a.tfar, h.u = a.u, h.v = a.v, h.Ng = Vec3(a.Ng_x, a.Ng_y, a.Ng_z);
  const auto it = c.index.find({a.geomID, a.primID});
  h.geomID = 0;
  h.primID = it == c.index.end() ? 0xFFFFFFFEu : it->second;  // a refused or unknown triangle: never right
  return h;
}

int compare(const Options& o, const std::string& ref_path, const std::string& test_path) {
  const CheckScene c = check_scene(o.moves() ? moved(load(o.scene), o.scatter) : load(o.scene), o.filter);
  std::vector<Ray> rays, test_rays;
  Answers ref, test;
  read_dump(ref_path, rays, ref);
  read_dump(test_path, test_rays, test);
  if (rays.size() != test_rays.size() || std::memcmp(rays.data(), test_rays.data(), rays.size() * sizeof(Ray)) != 0)
    return std::fprintf(stderr, "the two runs traced different rays\n"), 1;
  int failures = 0;
  for (int form = 0; form < kFormCount; ++form)
    for (Query q : {Query::Closest, Query::Any}) {
      const auto& a = test[2 * form + (q == Query::Any)];
      const auto& b = ref[2 * form + (q == Query::Any)];
      std::vector<Hit> ours(rays.size()), theirs(rays.size());
      size_t inst_bad = 0;
      for (size_t i = 0; i < rays.size(); ++i) {
        ours[i] = as_hit(a[i], q, c), theirs[i] = as_hit(b[i], q, c);
        // Fields Embree leaves alone on a miss and sets on a hit must match exactly, except
        // where one system hits and the other misses and the oracle takes either answer or
        // finds Embree's float test wrong there (a ray through an edge, a grazing ray the
        // exact test says misses).
        const bool hit_differs = (a[i].geomID == RTC_INVALID_GEOMETRY_ID) != (b[i].geomID == RTC_INVALID_GEOMETRY_ID);
        if (q == Query::Closest && (a[i].instID != b[i].instID || hit_differs)) {
          const HitVerdict::Outcome verdict = hit_differs ? compare_hit(c.scene, rays[i], q, ours[i], theirs[i], [&] {
                                                              return exact_answer(c.scene, rays[i]);
                                                            }).outcome
                                                          : HitVerdict::Mismatch;
          const bool explained = verdict == HitVerdict::EmbreeImprecise || verdict == HitVerdict::EdgeTie;
          if (!explained && inst_bad++ == 0)
            std::printf("  ray %zu: instID %u geomID %u t=%.9g against the reference's instID %u geomID %u t=%.9g\n", i,
                        a[i].instID, a[i].geomID, a[i].tfar, b[i].instID, b[i].geomID, b[i].tfar);
        }
      }
      // Embree's float normal of a thin or far-off triangle can be off by more than the
      // oracle's 1e-4; where kmbvh's is nearer the exact one, the difference is Embree's.
      size_t normal_imprecise = 0;
      for (size_t i = 0; i < rays.size(); ++i)
        if (q == Query::Closest && ours[i].found() && ours[i].primID == theirs[i].primID &&
            ours[i].primID < c.scene.triangles.size() &&
            normal_error(c.scene, ours[i].primID, ours[i].Ng) < normal_error(c.scene, ours[i].primID, theirs[i].Ng))
          theirs[i].Ng = ours[i].Ng, ++normal_imprecise;
      const HitComparison r = compare_hits(c.scene, rays, q, ours, theirs);
      const char* what = q == Query::Any ? "occluded" : "intersect";
      std::printf("%s%-3s %zu rays, %zu hits: %zu mismatches, %zu edge ties, %zu Embree-imprecise (%zu normals), "
                  "%zu instID/miss differences\n",
                  what, kForms[form], r.rays, r.hits, r.mismatches(), r.edge_ties, r.embree_imprecise + normal_imprecise,
                  normal_imprecise, inst_bad);
      for (const RayMismatch& m : r.first)
        std::printf("  ray %zu: %s (ours t=%.9g prim=%u Ng=%.9g %.9g %.9g, reference t=%.9g prim=%u Ng=%.9g %.9g %.9g)\n",
                    m.index, m.kind.c_str(), m.ours.t, m.ours.primID, m.ours.Ng.x, m.ours.Ng.y, m.ours.Ng.z,
                    m.reference.t, m.reference.primID, m.reference.Ng.x, m.reference.Ng.y, m.reference.Ng.z);
      failures += r.mismatches() > 0 || inst_bad > 0;
      // Under kmbvh every form is the same traversal: exactly rtcIntersect1's answers.
      if (o.exact_forms && form > 0) {
        const auto& single = test[q == Query::Any];
        size_t differ = 0;
        for (size_t i = 0; i < rays.size(); ++i) differ += !(a[i] == single[i]);
        if (differ) std::printf("  %zu answers differ from %s1's\n", differ, what), ++failures;
      }
    }
  std::printf(failures ? "FAILED\n" : "PASSED\n");
  return failures ? 1 : 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    if (argc < 4)
      throw std::invalid_argument("usage: scene_client trace SCENE OUT | compare SCENE REF TEST | time SCENE RUNS [options]");
    const std::string mode = argv[1];
    Options o;
    o.scene = argv[2];
    std::vector<std::string> files;
    for (int i = 3; i < argc; ++i) {
      const std::string a = argv[i];
      if (a == "--filter") o.filter = true;
      else if (a == "--quad") o.quad = true;
      else if (a == "--exact-forms") o.exact_forms = true;
      else if (a == "--dynamic") o.dynamic = true;
      else if (a == "--scatter") o.dynamic = o.scatter = true;
      else if (a == "--refit-quality") o.refit_quality = true;
      else if (a == "--low") o.low = true;
      else if (a == "--recommit") o.recommit = true;
      else if (a.rfind("--", 0) == 0) throw std::invalid_argument("unknown option " + a);
      else files.push_back(a);
    }
    if (mode == "trace" && files.size() == 1) return trace(o, files[0]);
    if (mode == "compare" && files.size() == 2) return compare(o, files[0], files[1]);
    if (mode == "time" && files.size() == 1) return time_forms(o, std::max(1, std::atoi(files[0].c_str())));
    throw std::invalid_argument("bad arguments");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "scene_client: %s\n", e.what());
    return 2;
  }
}
