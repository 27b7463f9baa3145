// One ray through a Bvh2: the while-while loop of Aila and Laine (2009). The inner loop
// walks interior nodes, entering the nearer child and pushing the farther one, until it
// reaches a leaf; the second loop intersects leaves until the next interior node comes
// off the stack. Written once for the CPU and the GPU (docs/design.md §3).
//
// The stack grows by at most one entry per level (only the farther child of a node is
// pushed), so the layout's stack_size, the depth of the tree plus one, always suffices:
// a deep tree needs a bigger stack, never a lucky ray.
#pragma once

#include "bvh2.h"
#include "ray_box.h"
#include "watertight.h"

namespace kmbvh {

struct TraversalEntry {
  uint32_t ref, count;  // as in Bvh2Node: count 0 is an interior node
  float entry;          // where the ray enters its box: skipped once a closer hit is known
};

// The hit on triangle `found`, with t, u, v and Ng from its exact check (`check`) unless
// `refine` is false: an occlusion query needs only the yes (as Embree's reports).
KMBVH_HD KMBVH_INLINE bool finish_bvh2_hit(const Bvh2View& view, uint32_t found, const ExactCheck& check, Hit& hit,
                                           bool refine = true) {
  if (found == kInvalidId) return false;
  const LeafTriangle& tri = view.triangles[found];
  if (refine) apply_exact_check(check, tri.a, tri.b, tri.c, hit);
  hit.geomID = view.ids[found].geom;
  hit.primID = view.ids[found].prim;
  return true;
}

// A closest-hit ray traced again with every triangle it reaches tested in double precision
// (intersect_watertight_exact), the closest by exact t: for the rare ray whose closest
// candidate the float test accepted while the exact measure puts the ray outside it (a
// needle seen along its length, watertight.h: outside_by_exact_check), where the float
// test may have passed the true closest hit too. The same descent as trace_bvh2, so the
// same stack bound.
KMBVH_HD KMBVH_INLINE bool trace_bvh2_exact(const Bvh2View& view, const Ray& ray, TraversalEntry* stack, Hit& hit) {
  hit = Hit();
  const RayBoxSetup boxes(ray);
  const RayShearExact shear(ray);
  double best = ray.tfar;
  float tmax = ray.tfar;  // the boxes' reach: a little past the closest exact t
  uint32_t found = kInvalidId;
  uint32_t sp = 0;
  TraversalEntry cur{0, 0, ray.tnear};
  for (;;) {
    if (cur.entry <= tmax) {
      if (cur.count == 0) {  // the nearer child next, the farther pushed, as trace_bvh2 descends
        const Bvh2Node& n = view.nodes[cur.ref];
        float e0, e1;
        const bool h0 = ray_enters_box(boxes, n.box[0], ray.tnear, tmax, e0);
        const bool h1 = ray_enters_box(boxes, n.box[1], ray.tnear, tmax, e1);
        if (h0 || h1) {
          const int near = h0 && h1 ? (e1 < e0 ? 1 : 0) : (h1 ? 1 : 0);
          if (h0 && h1) stack[sp++] = TraversalEntry{n.ref[1 - near], n.count[1 - near], near ? e0 : e1};
          cur = TraversalEntry{n.ref[near], n.count[near], near ? e1 : e0};
          continue;
        }
      } else {
        for (uint32_t i = cur.ref; i < cur.ref + cur.count; ++i) {
          const LeafTriangle& tri = view.triangles[i];
          double t;
          if (!intersect_watertight_exact(shear, ray.tnear, best, tri.a, tri.b, tri.c, t)) continue;
          best = t, found = i;
          // The boxes are tested in float: they keep a margin past the exact t (the wide
          // kernel's cull_reach, 2^-13 of it), as float(best) and a box's exit may round down.
          tmax = float(best) * (1.0f + 0x1p-13f);
        }
      }
    }
    if (sp == 0) break;
    cur = stack[--sp];
  }
  ExactCheck check;
  if (found != kInvalidId) {
    const LeafTriangle& tri = view.triangles[found];
    check = exact_check(ray, tri.a, tri.b, tri.c, ray.tnear, ray.tfar);
    hit.t = float(best);
  }
  return finish_bvh2_hit(view, found, check, hit);
}

// The answer once the float descent is over: its closest candidate, unless the exact
// measure doubts it (trace_bvh2_exact).
KMBVH_HD KMBVH_INLINE bool conclude_bvh2(const Bvh2View& view, const Ray& ray, Query query, TraversalEntry* stack,
                                         uint32_t found, const ExactCheck& check, Hit& hit) {
  if (query == Query::Closest && found != kInvalidId && outside_by_exact_check(check))
    return trace_bvh2_exact(view, ray, stack, hit);
  return finish_bvh2_hit(view, found, check, hit);
}

// Closest hit (query Closest) or any hit (query Any) within [ray.tnear, ray.tfar].
// `stack` holds view.stack_size entries. Returns whether a hit was found; for Closest,
// `hit` holds it, refined; for Any, the occluding triangle and its float t.
KMBVH_HD KMBVH_INLINE bool trace_bvh2(const Bvh2View& view, const Ray& ray, Query query, TraversalEntry* stack,
                                      Hit& hit) {
  hit = Hit();
  if (view.node_count == 0 || !ray_can_hit(ray)) return false;
  const RayBoxSetup boxes(ray);
  const RayShear shear(ray);
  float tmax = ray.tfar;
  uint32_t found = kInvalidId;  // the closest hit's triangle so far
  ExactCheck check;             // and its exact check
  uint32_t sp = 0;
  TraversalEntry cur{0, 0, ray.tnear};
  for (;;) {
    while (cur.count == 0) {  // interior nodes
      const Bvh2Node& n = view.nodes[cur.ref];
      float e0, e1;
      const bool h0 = ray_enters_box(boxes, n.box[0], ray.tnear, tmax, e0);
      const bool h1 = ray_enters_box(boxes, n.box[1], ray.tnear, tmax, e1);
      if (h0 && h1) {
        const int near = e1 < e0 ? 1 : 0;
        stack[sp++] = TraversalEntry{n.ref[1 - near], n.count[1 - near], near ? e0 : e1};
        cur = TraversalEntry{n.ref[near], n.count[near], near ? e1 : e0};
      } else if (h0 || h1) {
        const int c = h1 ? 1 : 0;
        cur = TraversalEntry{n.ref[c], n.count[c], c ? e1 : e0};
      } else {
        do {
          if (sp == 0) return conclude_bvh2(view, ray, query, stack, found, check, hit);
          cur = stack[--sp];
        } while (cur.entry > tmax);
      }
    }
    while (cur.count != 0) {  // leaves
      for (uint32_t i = cur.ref; i < cur.ref + cur.count; ++i) {
        const LeafTriangle& tri = view.triangles[i];
        Hit candidate;
        if (!intersect_watertight(shear, ray.tnear, tmax, tri.a, tri.b, tri.c, candidate)) continue;
        // Occlusion reports no t, u or v: the cheaper check of the interval alone.
        ExactCheck exact;
        if (query == Query::Any) {
          if (!exact_within(ray, tri.a, tri.b, tri.c, ray.tnear, tmax)) continue;
        } else {
          exact = exact_check(ray, tri.a, tri.b, tri.c, ray.tnear, tmax);
          if (!exact.within) continue;
        }
        found = i;
        check = exact;
        hit = candidate;
        if (query == Query::Any) break;
        tmax = hit.t;
      }
      if (query == Query::Any && found != kInvalidId) return finish_bvh2_hit(view, found, check, hit, false);
      do {
        if (sp == 0) return conclude_bvh2(view, ray, query, stack, found, check, hit);
        cur = stack[--sp];
      } while (cur.entry > tmax);
    }
  }
}

}  // namespace kmbvh
