// The path tracer's per-path kernels (docs/design.md §6): a wavefront of paths, one
// work item per path, written once for the CPU and the GPU. Paths are diffuse: at each hit
// the path adds the surface's emission, sends `shadow_samples` shadow rays to the area
// light (next-event estimation), and continues in a cosine-weighted direction, ended by
// Russian roulette from `roulette_depth` surfaces on. The light is reached only through
// shadow rays and the sky only by escaping, so no light is counted twice.
//
// Randomness is counter-based (docs/design.md §3): draw `dim` at `depth` of the path of `pixel`
// in sample pass `key` (a hash of seed, view and pass). An image is then the same for any
// thread count, wave size and traversal that reports the same triangles.
#pragma once

#include <cstdint>

#include "cuda/core/counter_rng.h"
#include "cuda/traversal/ray.h"
#include "camera.h"
#include "lighting.h"
#include "material.h"
#include "sampling.h"
#include "surface.h"

namespace kmbvh {

constexpr uint32_t kMaxShadowSamples = 4;

// Draws of one path segment: two per shadow sample, then the bounce, roulette, pixel jitter.
enum PathDraw : uint32_t {
  kDrawLight = 0,  // 2 * kMaxShadowSamples of them
  kDrawBounce = 2 * kMaxShadowSamples,
  kDrawRoulette = kDrawBounce + 2,
  kDrawJitter = kDrawRoulette + 1,
  kDrawsPerSegment = kDrawJitter + 2,
};

KMBVH_HD KMBVH_INLINE uint32_t pass_key(uint32_t seed, uint32_t view, uint32_t pass) {
  return counter_hash(seed, view, pass);
}

KMBVH_HD KMBVH_INLINE float path_draw(uint32_t key, uint32_t depth, uint32_t dim, uint32_t pixel) {
  return counter_unit(key, depth * kDrawsPerSegment + dim, pixel);
}

struct PathLimits {
  uint32_t max_depth = 32;      // surfaces a path may hit (a bound for termination, rarely reached)
  uint32_t roulette_depth = 3;  // surfaces hit before Russian roulette starts
  uint32_t shadow_samples = 2;  // shadow rays per hit (docs/design.md §6: 2), at most kMaxShadowSamples
};

// The scene as the shading kernel reads it: plain pointers on the backend's side.
struct ShadingView {
  const Vec3* positions = nullptr;
  const uint32_t* indices = nullptr;            // three per triangle
  const uint32_t* triangle_material = nullptr;  // null: materials[0] for every triangle
  const Material* materials = nullptr;
  Lighting lighting;
  float diagonal = 0;  // of the scene's bounds: scales the offset of leaving rays
};

struct PathState {
  Ray ray;          // the path's next ray
  Vec3 throughput;  // the weight of radiance found from here on
  Vec3 radiance;    // found so far
  uint32_t pixel = 0;
  uint32_t depth = 0;  // surfaces hit so far
  uint32_t alive = 0;  // whether `ray` is still to be traced
};

KMBVH_HD KMBVH_INLINE float max_component(Vec3 v) { return max(v.x, max(v.y, v.z)); }

// A ray that cannot hit anything (an empty interval): the unused shadow slot of a path.
KMBVH_HD KMBVH_INLINE Ray no_ray() {
  Ray r;
  r.tnear = 1.0f;
  r.tfar = 0.0f;
  return r;
}

// Path `i` of a wave: pixel first_pixel + i of a width x height image, through a jittered
// point of the pixel.
struct StartPaths {
  Camera camera;
  uint32_t width, height, first_pixel, key;
  PathState* paths;
  uint32_t* active;
  KMBVH_HD void operator()(uint32_t i) const {
    const uint32_t pixel = first_pixel + i;
    const float x = (float(pixel % width) + path_draw(key, 0, kDrawJitter, pixel)) / float(width);
    const float y = (float(pixel / width) + path_draw(key, 0, kDrawJitter + 1, pixel)) / float(height);
    PathState& p = paths[i];
    p.ray = camera.ray(x, y);
    p.throughput = Vec3(1.0f);
    p.radiance = Vec3(0.0f);
    p.pixel = pixel;
    p.depth = 0;
    p.alive = 1;
    active[i] = i;
  }
};

// rays[j] = the ray of the j-th live path, so the traversal gets one dense batch.
struct GatherRays {
  const PathState* paths;
  const uint32_t* active;
  Ray* rays;
  KMBVH_HD void operator()(uint32_t j) const { rays[j] = paths[active[j]].ray; }
};

// The j-th live path meets hits[j]: sky or surface, emission, shadow rays into slots
// shadow_samples * j + s (weight zero where a slot has no ray), and the next ray.
struct ShadeHits {
  ShadingView scene;
  PathLimits limits;
  uint32_t key;
  const uint32_t* active;
  const Hit* hits;
  PathState* paths;
  Ray* shadow_rays;
  Vec3* shadow_weights;

  KMBVH_HD void operator()(uint32_t j) const {
    PathState& p = paths[active[j]];
    const uint32_t S = limits.shadow_samples;
    for (uint32_t s = 0; s < S; ++s) {
      shadow_rays[S * j + s] = no_ray();
      shadow_weights[S * j + s] = Vec3(0.0f);
    }
    const Hit& h = hits[j];
    if (!h.found()) {
      p.radiance = p.radiance + p.throughput * scene.lighting.sky.radiance(p.ray.dir);
      p.alive = 0;
      return;
    }
    const uint32_t* v = scene.indices + 3 * size_t(h.primID);
    const SurfacePoint surface = surface_point(p.ray, scene.positions[v[0]], scene.positions[v[1]],
                                               scene.positions[v[2]], h.t, scene.diagonal);
    const Material m = scene.materials[scene.triangle_material ? scene.triangle_material[h.primID] : 0];
    p.radiance = p.radiance + p.throughput * m.emission;
    if (!(dot(surface.normal, surface.normal) > 0.0f)) {  // no plane to reflect from
      p.alive = 0;
      return;
    }
    // Next-event estimation: points on the light, uniform by area.
    const QuadLight& light = scene.lighting.light;
    const Vec3 reflected = p.throughput * m.albedo * (1.0f / 3.14159265f);
    if (light.area > 0.0f) {
      for (uint32_t s = 0; s < S; ++s) {
        const Vec3 q = light.point(path_draw(key, p.depth, kDrawLight + 2 * s, p.pixel),
                                   path_draw(key, p.depth, kDrawLight + 2 * s + 1, p.pixel));
        const Vec3 d = q - surface.origin;
        const float distance2 = dot(d, d);
        if (!(distance2 > 0.0f)) continue;
        const float distance = sqrtf(distance2);
        const Vec3 dir = d * (1.0f / distance);
        const float cos_surface = dot(surface.normal, dir);
        const float cos_light = -dot(light.normal, dir);
        if (cos_surface <= 0.0f || cos_light <= 0.0f) continue;
        Ray r;
        r.org = surface.origin;
        r.dir = dir;
        r.tnear = 0.0f;
        r.tfar = distance * (1.0f - 1e-4f);
        shadow_rays[S * j + s] = r;
        shadow_weights[S * j + s] =
            reflected * light.radiance * (cos_surface * cos_light * light.area / (distance2 * float(S)));
      }
    }
    // The bounce: cosine-weighted, so the weight is the albedo alone.
    const uint32_t depth = p.depth + 1;
    Vec3 throughput = p.throughput * m.albedo;
    if (depth >= limits.max_depth || !(max_component(throughput) > 0.0f)) {
      p.alive = 0;
      return;
    }
    if (depth >= limits.roulette_depth) {
      const float survive = min(0.95f, max_component(throughput));
      if (path_draw(key, p.depth, kDrawRoulette, p.pixel) >= survive) {
        p.alive = 0;
        return;
      }
      throughput = throughput * (1.0f / survive);
    }
    p.ray.org = surface.origin;
    p.ray.dir = cosine_direction(surface.normal, path_draw(key, p.depth, kDrawBounce, p.pixel),
                                 path_draw(key, p.depth, kDrawBounce + 1, p.pixel));
    p.ray.tnear = 0.0f;
    p.ray.tfar = INFINITY;
    p.throughput = throughput;
    p.depth = depth;
  }
};

// Whether shadow slot k holds a ray (a non-zero weight).
struct HasShadowRay {
  const Vec3* weights;
  KMBVH_HD bool operator()(uint32_t k) const { return max_component(weights[k]) > 0.0f; }
};

// packed[q] = the ray of the q-th used shadow slot.
struct GatherShadowRays {
  const uint32_t* slots;
  const Ray* slot_rays;
  Ray* packed;
  KMBVH_HD void operator()(uint32_t q) const { packed[q] = slot_rays[slots[q]]; }
};

// occluded[slot] of the q-th used slot, from its any-hit answer.
struct ScatterOcclusion {
  const uint32_t* slots;
  const Hit* packed_hits;
  uint8_t* occluded;
  KMBVH_HD void operator()(uint32_t q) const { occluded[slots[q]] = packed_hits[q].found() ? 1 : 0; }
};

// The j-th live path adds the light its unoccluded shadow rays see; a path that has ended
// adds what it found to its pixel. Each pixel has one path per pass, so no two work items
// write one pixel.
struct AddLight {
  uint32_t shadow_samples;
  const uint32_t* active;
  const Vec3* shadow_weights;
  const uint8_t* occluded;
  PathState* paths;
  Vec3* film;
  KMBVH_HD void operator()(uint32_t j) const {
    PathState& p = paths[active[j]];
    for (uint32_t s = 0; s < shadow_samples; ++s) {
      const uint32_t k = shadow_samples * j + s;
      if (max_component(shadow_weights[k]) > 0.0f && !occluded[k]) p.radiance = p.radiance + shadow_weights[k];
    }
    if (!p.alive) film[p.pixel] = film[p.pixel] + p.radiance;
  }
};

struct IsAlive {
  const PathState* paths;
  KMBVH_HD bool operator()(uint32_t slot) const { return paths[slot].alive != 0; }
};

}  // namespace kmbvh
