#include "scene_survey.h"

#include <algorithm>
#include <cmath>

#include "adapters/builder_registry.h"
#include "adapters/out/tracer.h"

namespace kmbvh {
namespace {

constexpr float kPi = 3.14159265f;

// Unit directions evenly over the sphere (a Fibonacci lattice).
std::vector<Vec3> sphere_directions(int n) {
  std::vector<Vec3> dirs;
  for (int i = 0; i < n; ++i) {
    const float z = 1.0f - 2.0f * (float(i) + 0.5f) / float(n), r = std::sqrt(1.0f - z * z);
    const float phi = 2.39996323f * float(i);
    dirs.emplace_back(r * std::cos(phi), z, r * std::sin(phi));
  }
  return dirs;
}

Vec3 horizontal(float angle) { return Vec3(std::cos(angle), 0.0f, std::sin(angle)); }

struct Sight {
  float distance;  // to the first surface, INFINITY where the ray escapes
  bool facing;     // that surface faces the ray's origin
};

// One batch: every point along every direction.
std::vector<Sight> look(const Tracer& tracer, const std::vector<Vec3>& points, const std::vector<Vec3>& dirs) {
  std::vector<Ray> rays;
  for (const Vec3& p : points)
    for (const Vec3& d : dirs) {
      Ray r;
      r.org = p;
      r.dir = d;
      r.tfar = INFINITY;
      rays.push_back(r);
    }
  std::vector<Hit> hits;
  tracer.trace(rays, Query::Closest, hits);
  std::vector<Sight> sights(hits.size());
  for (size_t i = 0; i < hits.size(); ++i)
    sights[i] = hits[i].found() ? Sight{hits[i].t, dot(hits[i].Ng, rays[i].dir) < 0.0f} : Sight{INFINITY, false};
  return sights;
}

// A small light facing down at height y over (x, z), bright enough that a white surface
// `drop` below it has radiance about 0.8 (irradiance 0.8 pi).
QuadLight light_over(float x, float z, float y, float side, float drop) {
  const float h = 0.5f * side, radiance = 0.8f * kPi * drop * drop / (side * side);
  if (!(side > 0.0f) || !std::isfinite(radiance)) return QuadLight();
  return QuadLight::facing_down(x - h, x + h, z - h, z + h, y, Vec3(radiance, radiance * 0.95f, radiance * 0.85f));
}

Sky default_sky() { return Sky{Vec3(0.16f, 0.25f, 0.45f), Vec3(0.4f, 0.44f, 0.5f)}; }

// Three views from outside the core's bounding sphere, and a light high above it.
void survey_object(SceneSurvey& s, float aspect) {
  const Vec3 c = s.core.center();
  const float radius = 0.5f * length(s.core.extent()), fov = 40.0f;
  const float distance = 0.95f * radius / std::sin(0.5f * fov * kPi / 180.0f);
  const float azimuth[kViewsPerScene] = {-0.6f, 2.2f, 3.8f}, elevation[kViewsPerScene] = {0.35f, 0.2f, 1.0f};
  for (int v = 0; v < kViewsPerScene; ++v) {
    const Vec3 dir(std::cos(elevation[v]) * std::sin(azimuth[v]), std::sin(elevation[v]),
                   std::cos(elevation[v]) * std::cos(azimuth[v]));
    s.views.push_back(Camera::look_at(c + dir * distance, c, fov, aspect));
  }
  s.middle = c;
  s.lighting.light = light_over(c.x, c.z, s.core.hi.y + 1.5f * radius, radius, 1.5f * radius + 0.5f * s.core.extent().y);
}

void survey_room(SceneSurvey& s, const Tracer& tracer, float aspect) {
  constexpr int kAround = 16;
  std::vector<Vec3> dirs{Vec3(0.0f, 1.0f, 0.0f), Vec3(0.0f, -1.0f, 0.0f)};
  for (int k = 0; k < kAround; ++k) dirs.push_back(horizontal(2.0f * kPi * float(k) / kAround));
  const std::vector<Sight> around = look(tracer, {s.middle}, dirs);
  const float size = length(s.core.extent());
  auto capped = [&](float d) { return std::min(d, size); };
  const float up = around[0].distance, down = capped(around[1].distance);
  std::vector<float> h(kAround);
  for (int k = 0; k < kAround; ++k) h[k] = capped(around[2 + k].distance);
  const int nave = int(std::max_element(h.begin(), h.end()) - h.begin());
  auto dist = [&](int k) { return h[((k % kAround) + kAround) % kAround]; };
  const Vec3 along = horizontal(2.0f * kPi * float(nave) / kAround);
  const Vec3 eye_height(0.0f, -0.2f * down, 0.0f);
  const Vec3 look_down(0.0f, -0.15f * down, 0.0f);
  // View 0 down the nave, view 2 back up it, view 1 from above across the room.
  s.views.push_back(Camera::look_at(s.middle - along * (0.6f * dist(nave + kAround / 2)) + eye_height,
                                    s.middle + along * (0.5f * dist(nave)) + look_down, 60.0f, aspect));
  const int across = nave + kAround / 4 + kAround / 8;
  const Vec3 side = horizontal(2.0f * kPi * float(across) / kAround);
  // Looking down at most about 30 degrees, so that the walls stay upright.
  const float headroom = std::isfinite(up) ? up : s.core.hi.y - s.middle.y;  // an open sky: stay under the roofs
  const float rise = 0.4f * std::max(0.0f, std::min(headroom, down)), reach = 0.5f * dist(across) + 0.4f * dist(across + kAround / 2);
  const float drop = std::min(rise + 0.6f * down, 0.6f * reach);
  const Vec3 eye1 = s.middle + side * (0.5f * dist(across)) + Vec3(0.0f, rise, 0.0f);
  s.views.push_back(Camera::look_at(eye1, eye1 - side * reach - Vec3(0.0f, drop, 0.0f), 60.0f, aspect));
  s.views.push_back(Camera::look_at(s.middle + along * (0.6f * dist(nave)) + eye_height,
                                    s.middle - along * (0.5f * dist(nave + kAround / 2)) + look_down, 60.0f, aspect));
  std::vector<float> sorted = h;
  std::nth_element(sorted.begin(), sorted.begin() + kAround / 2, sorted.end());
  const float side_length = 0.3f * sorted[kAround / 2];
  if (std::isfinite(up)) {  // under the ceiling
    s.lighting.light = light_over(s.middle.x, s.middle.z, s.middle.y + 0.9f * up, side_length, 0.9f * up + down);
  } else {  // open to the sky: a sun high above
    const float height = s.core.hi.y + 0.5f * size;
    s.lighting.light = light_over(s.middle.x, s.middle.z, height, 0.25f * size, height - (s.middle.y - down));
  }
}

}  // namespace

const char* to_string(SceneKind kind) { return kind == SceneKind::Interior ? "interior" : "object"; }

SceneSurvey survey_scene(const TriangleScene& scene, const PrimitiveSet& prims, float aspect) {
  SceneSurvey s;
  s.core = core_bounds(prims);
  s.lighting.sky = default_sky();
  if (prims.empty()) {
    survey_object(s, aspect);
    return s;
  }
  const Tracer tracer(run_builder(parse_builder("lbvh"), prims), prims, scene, Layout::Bvh2);
  // Candidate middles: a 5 x 5 x 5 grid inside the core.
  constexpr int kGrid = 5, kDirs = 64;
  std::vector<Vec3> candidates;
  for (int x = 0; x < kGrid; ++x)
    for (int y = 0; y < kGrid; ++y)
      for (int z = 0; z < kGrid; ++z) {
        const Vec3 f((float(x) + 1.0f) / (kGrid + 1), (float(y) + 1.0f) / (kGrid + 1), (float(z) + 1.0f) / (kGrid + 1));
        candidates.push_back(s.core.lo + s.core.extent() * f);
      }
  const std::vector<Sight> sights = look(tracer, candidates, sphere_directions(kDirs));
  const float size = length(s.core.extent());
  float best = -1.0f;
  for (size_t c = 0; c < candidates.size(); ++c) {
    int hits = 0, facing = 0;
    float openness = 0;
    for (int d = 0; d < kDirs; ++d) {
      const Sight& sight = sights[c * kDirs + d];
      openness += std::min(sight.distance, size);
      if (!std::isfinite(sight.distance)) continue;
      ++hits;
      facing += sight.facing;
    }
    // Enclosed (at most a quarter of the sky open: a courtyard, a street) by walls seen
    // from their front; outside a building half the rays escape.
    const bool in_room = 4 * hits >= 3 * kDirs && 5 * facing >= 4 * hits;
    if (in_room && openness > best) {
      best = openness;
      s.middle = candidates[c];
    }
  }
  s.kind = best >= 0.0f ? SceneKind::Interior : SceneKind::Object;
  if (s.kind == SceneKind::Interior)
    survey_room(s, tracer, aspect);
  else
    survey_object(s, aspect);
  return s;
}

}  // namespace kmbvh
