#include "build_bvh.h"

#include <fmt/format.h>
#include <omp.h>

#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstring>

#include "adapters/builder_api/build_primitives.h"
#include "adapters/builder_api/embree_callbacks.h"
#include "bvh_object.h"
#include "device_errors.h"
#include "plugin_config.h"

namespace kmbvh::plugin {
namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); }

// The largest leaf kmbvh's builders make for the application. The SAH pass in
// emit_to_callbacks then merges subtrees into leaves up to the application's maxLeafSize
// where the application's costs say so; leaves built larger could never be split again.
// 2 rather than 1: on sponza_dabrovic the SAH cost is within 0.5% and the build 20% faster.
constexpr uint32_t kBuilderLeafSize = 2;

// Embree 3 makes nodes of up to 16 children and refuses more (0 and 1 mean 2).
constexpr uint32_t kMaxBranchingFactor = 16;

// The quality read as the integer a C caller may have stored: any value outside the enum's
// is refused, and reading it through the enum type would already be undefined.
bool is_build_quality(const RTCBuildArguments& a) {
  int q = 0;
  static_assert(sizeof(a.buildQuality) == sizeof(q), "RTCBuildQuality is an int-sized enum");
  std::memcpy(&q, &a.buildQuality, sizeof q);
  return q == RTC_BUILD_QUALITY_LOW || q == RTC_BUILD_QUALITY_MEDIUM || q == RTC_BUILD_QUALITY_HIGH;
}

// Embree's checks, in Embree's order and with its codes and messages (Embree 3.13,
// rtcore_builder.cpp); where Embree crashes or asserts instead, the error it reports for
// the nearest case.
void check_arguments(const RTCBuildArguments& a) {
  if (!a.createNode || !a.setNodeChildren || !a.setNodeBounds || !a.createLeaf)
    throw EmbreeError(RTC_ERROR_INVALID_ARGUMENT, "invalid argument");
  if (a.primitiveArrayCapacity < a.primitiveCount)
    throw EmbreeError(RTC_ERROR_INVALID_ARGUMENT, "primitiveArrayCapacity must be greater or equal to primitiveCount");
  if (!is_build_quality(a))
    throw EmbreeError(RTC_ERROR_INVALID_OPERATION, "invalid build quality");
  if (a.primitiveCount > 0 && !a.primitives)
    throw EmbreeError(RTC_ERROR_INVALID_ARGUMENT, "primitives is NULL but primitiveCount is not 0");
  if (!std::isfinite(a.traversalCost) || !std::isfinite(a.intersectionCost) || a.traversalCost < 0 ||
      a.intersectionCost < 0)
    throw EmbreeError(RTC_ERROR_INVALID_ARGUMENT, "traversalCost and intersectionCost must be finite and not negative");
  if (a.primitiveCount > 0 && (a.maxLeafSize == 0 || a.maxDepth == 0))
    throw EmbreeError(RTC_ERROR_UNKNOWN, a.maxLeafSize == 0 ? "depth limit reached (maxLeafSize is 0)"
                                                             : "depth limit reached (maxDepth is 0)");
  if (a.maxBranchingFactor > kMaxBranchingFactor)
    throw EmbreeError(RTC_ERROR_UNKNOWN, "bvh_builder: branching factor too large");
}

bool keep_going(const RTCBuildArguments& a, double fraction) {
  return !a.buildProgress || a.buildProgress(a.userPtr, fraction);
}

void* build(BvhObject& object, const RTCBuildArguments& a) {
  check_arguments(a);
  const auto start = Clock::now();
  if (!keep_going(a, 0.0)) throw EmbreeError(RTC_ERROR_CANCELLED, "build cancelled");
  const PrimitiveSet prims = [&] {
    try {
      return primitive_set_from(a.primitives, a.primitiveCount);
    } catch (const std::invalid_argument& e) {
      throw EmbreeError(RTC_ERROR_INVALID_ARGUMENT, e.what());
    }
  }();

  const PluginConfig& config = plugin_config();
  BuilderConfig builder = builder_for(config, a.buildQuality, BuildPath::BuilderApi);
  builder.max_leaf_size = std::min(std::max(a.maxLeafSize, 1u), kBuilderLeafSize);
  builder.kmeans.wide = false;  // binary, widened to maxBranchingFactor by the SAH (embree_callbacks.h)
  builder.binary.sah = SahCosts{a.traversalCost, a.intersectionCost};
  BuildInfo info;
  const Bvh bvh = run_builder(builder, prims, &info, &object.build_context());
  const double build_ms = ms_since(start);
  if (!keep_going(a, 0.5)) throw EmbreeError(RTC_ERROR_CANCELLED, "build cancelled");

  // Embree frees the previous tree of this BVH object when it builds again.
  const size_t threads = size_t(omp_get_max_threads());
  object.start_build(threads, prims.size());
  std::vector<RTCThreadLocalAllocator> allocators(threads);
  for (size_t t = 0; t < threads; ++t) allocators[t] = object.allocator(t);
  EmitLimits limits;
  limits.branching = a.maxBranchingFactor;
  limits.min_leaf = std::min(a.minLeafSize, a.maxLeafSize);
  limits.max_leaf = a.maxLeafSize;
  limits.max_depth = a.maxDepth;
  limits.traversal_cost = a.traversalCost;
  limits.intersection_cost = a.intersectionCost;
  const EmbreeCallbacks callbacks{a.createNode, a.setNodeChildren, a.setNodeBounds, a.createLeaf, a.userPtr};
  EmitResult emitted;
  struct Emitting {  // cleared however the emission ends
    BvhObject& object;
    explicit Emitting(BvhObject& o) : object(o) { object.set_emitting(true); }
    ~Emitting() { object.set_emitting(false); }
  } emitting(object);
  try {
    emitted = emit_to_callbacks(bvh, prims, a.primitives, limits, callbacks, allocators, &object.build_context());
  } catch (const DepthLimitError& e) {
    throw EmbreeError(RTC_ERROR_UNKNOWN, e.what());
  }
  if (!keep_going(a, 1.0)) throw EmbreeError(RTC_ERROR_CANCELLED, "build cancelled");
  if (config.log)
    log_line(fmt::format("rtcBuildBVH: {}, {} primitives, {:.2f} ms (build {:.2f} ms, callbacks {:.2f} ms), SAH {:.2f}, "
                         "{} nodes, {} leaves, depth {}, {} backend allocations{}",
                         builder.label(), prims.size(), ms_since(start), build_ms, ms_since(start) - build_ms,
                         emitted.sah_cost, emitted.inner_nodes, emitted.leaves, emitted.depth, info.backend.allocations,
                         emitted.rebalanced ? fmt::format(", {} subtrees rebalanced for maxDepth", emitted.rebalanced)
                                            : std::string()));
  return emitted.root;
}

}  // namespace

void* build_bvh(const RTCBuildArguments* args) {
  // Embree 3 never reads byteSize (an application may leave it 0), and neither does kmbvh.
  if (!args) {
    report_error(nullptr, RTC_ERROR_INVALID_ARGUMENT, "invalid argument");
    return nullptr;
  }
  BvhObject* object = BvhObject::from(args->bvh);
  if (!object) {
    report_error(nullptr, RTC_ERROR_INVALID_ARGUMENT, "invalid argument");
    return nullptr;
  }
  void* root = nullptr;
  guarded(object->device(), [&] { root = build(*object, *args); });
  return root;
}

}  // namespace kmbvh::plugin
