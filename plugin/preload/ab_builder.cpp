#include "ab_builder.h"

#include <atomic>
#include <chrono>
#include <mutex>
#include <vector>

#include "ab_report.h"
#include "kmbvh/embree.h"
#include "plugin/bvh_object.h"
#include "plugin/plugin_config.h"
#include "plugin/real_embree.h"
#include "tree_capture.h"

namespace kmbvh::plugin {
namespace {

std::atomic<bool> embree_building{false};

// A/B builds one at a time: embree_building says whose allocators are in use.
std::mutex& build_mutex() {
  static std::mutex* m = new std::mutex;  // never destroyed: builds may run during exit
  return *m;
}

RTCBVH twin_of(BvhObject& object) {
  if (!object.twin()) {
    RTCBVH twin = KMBVH_REAL_EMBREE(rtcNewBVH)(object.device());
    if (!twin) return nullptr;
    object.set_twin(std::shared_ptr<RTCBVHTy>(twin, [](RTCBVH b) { KMBVH_REAL_EMBREE(rtcReleaseBVH)(b); }));
  }
  return object.twin();
}

using Clock = std::chrono::steady_clock;

struct Built {
  void* root = nullptr;
  double ms = 0;
  std::optional<TreeStats> stats;
};

Built build_kmbvh(TreeCapture& capture, RTCBVH bvh, RTCBuildPrimitive* prims, bool answering) {
  const RTCBuildArguments a = capture.wrapped(bvh, prims, answering);
  const auto start = Clock::now();
  Built b;
  b.root = kmbvhBuildBVH(&a);
  b.ms = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
  if (b.root) b.stats = capture.stats(b.root);
  return b;
}

Built build_embree(TreeCapture& capture, RTCBuildPrimitive* prims, bool answering, RTCBVH twin) {
  const RTCBuildArguments a = capture.wrapped(twin, prims, answering);
  const auto start = Clock::now();
  Built b;
  struct Building {  // cleared however the build ends (an application's callback may throw through it)
    Building() { embree_building.store(true); }
    ~Building() { embree_building.store(false); }
  };
  {
    const Building building;
    b.root = KMBVH_REAL_EMBREE(rtcBuildBVH)(&a);
  }
  b.ms = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
  if (b.root) b.stats = capture.stats(b.root);
  return b;
}

BuildSide side_of(const Built& b) { return BuildSide{b.root != nullptr, b.ms, b.stats}; }

}  // namespace

bool embree_is_building() { return embree_building.load(std::memory_order_relaxed); }

void* ab_build_bvh(const RTCBuildArguments* args) {
  BvhObject* object = args ? BvhObject::from(args->bvh) : nullptr;
  if (!object || !args->primitives || !args->createNode || !args->setNodeChildren || !args->setNodeBounds ||
      !args->createLeaf)
    return kmbvhBuildBVH(args);  // refused with Embree's error, by kmbvh alone
  std::lock_guard<std::mutex> lock(build_mutex());
  report_ab_at_exit();
  const bool embree_answers = plugin_config().ab.embree_answers;
  RTCBVH twin = twin_of(*object);
  if (!twin) return kmbvhBuildBVH(args);  // Embree could not make its object (it reported why)
  // The other system builds on a copy: both builders reorder the array in place, and the
  // application may read its primitives back through the tree it receives.
  std::vector<RTCBuildPrimitive> copy(args->primitives, args->primitives + args->primitiveCount);
  copy.resize(args->primitiveArrayCapacity);  // room for Embree's splits, as the application gave it
  TreeCapture ours(*args), theirs(*args);
  Built k, e;
  if (embree_answers) {
    e = build_embree(theirs, args->primitives, true, twin);
    if (e.root) k = build_kmbvh(ours, args->bvh, copy.data(), false);
  } else {
    k = build_kmbvh(ours, args->bvh, args->primitives, true);
    if (k.root) e = build_embree(theirs, copy.data(), false, twin);
  }
  try {
    const std::string builder = builder_for(plugin_config(), args->buildQuality, BuildPath::BuilderApi).label();
    ab_note_build(BuildComparison{args->primitiveCount, args->buildQuality, builder, embree_answers, side_of(k),
                                  side_of(e)});
  } catch (...) {  // out of memory for the report: this build goes unreported
  }
  return embree_answers ? e.root : k.root;
}

}  // namespace kmbvh::plugin
