// Bad arguments to the builder API give the error Embree gives for them, through the same
// channels: rtcGetDeviceError and the device's error function (or, without a device, the
// thread's error read with rtcGetDeviceError(NULL)). Where Embree itself crashes or asserts
// on an argument, kmbvh reports RTC_ERROR_INVALID_ARGUMENT instead and the case is
// checked against that.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <functional>

#include "app_tree_check.h"
#include "support/scenes.h"

namespace kmbvh::test {
namespace {

struct Outcome {
  bool returned = false;  // a non-null tree (or BVH)
  RTCError device_error = RTC_ERROR_NONE;
  RTCError thread_error = RTC_ERROR_NONE;  // rtcGetDeviceError(NULL)
  std::vector<RTCError> callbacks;
};

std::ostream& operator<<(std::ostream& os, const Outcome& o) {
  os << "{returned " << o.returned << ", device error " << o.device_error << ", thread error " << o.thread_error
     << ", callbacks";
  for (RTCError e : o.callbacks) os << " " << e;
  return os << "}";
}

bool operator==(const Outcome& a, const Outcome& b) {
  return a.returned == b.returned && a.device_error == b.device_error && a.thread_error == b.thread_error &&
         a.callbacks == b.callbacks;
}

using Mutation = std::function<void(RTCBuildArguments&, std::vector<RTCBuildPrimitive>&)>;

// Builds 100 unit boxes in a row with `api`, after `mutate` has spoilt the arguments.
Outcome build_with(const app::BuilderApi& api, const Mutation& mutate,
                   RTCBuildQuality quality = RTC_BUILD_QUALITY_MEDIUM) {
  Outcome o;
  RTCDevice device = rtcNewDevice(nullptr);
  rtcSetDeviceErrorFunction(
      device, [](void* user, RTCError code, const char*) { static_cast<Outcome*>(user)->callbacks.push_back(code); }, &o);
  RTCBVH bvh = api.new_bvh(device);
  std::vector<RTCBuildPrimitive> prims;
  for (uint32_t i = 0; i < 100; ++i) prims.push_back(RTCBuildPrimitive{float(i), 0, 0, 0, float(i) + 1, 1, 1, i});
  app::BuildContext ctx{&api};
  RTCBuildArguments args = app::build_arguments(bvh, prims.data(), prims.size(), &ctx, quality);
  args.maxLeafSize = 4;
  mutate(args, prims);
  o.returned = api.build(&args) != nullptr;
  o.device_error = rtcGetDeviceError(device);
  o.thread_error = rtcGetDeviceError(nullptr);
  api.release(bvh);
  rtcReleaseDevice(device);
  return o;
}

struct Case {
  const char* name;
  Mutation mutate;
};

// Cases Embree answers without crashing: kmbvh must answer the same.
const Case kSameAsEmbree[] = {
    {"valid", [](auto&, auto&) {}},
    {"no_createNode", [](auto& a, auto&) { a.createNode = nullptr; }},
    {"no_setNodeChildren", [](auto& a, auto&) { a.setNodeChildren = nullptr; }},
    {"no_setNodeBounds", [](auto& a, auto&) { a.setNodeBounds = nullptr; }},
    {"no_createLeaf", [](auto& a, auto&) { a.createLeaf = nullptr; }},
    {"capacity_below_count", [](auto& a, auto&) { a.primitiveArrayCapacity = a.primitiveCount - 1; }},
    {"quality_refit", [](auto& a, auto&) { a.buildQuality = RTC_BUILD_QUALITY_REFIT; }},
    {"quality_out_of_range", [](auto& a, auto&) {
       const int q = 7;  // as a C caller can store it (a cast to the enum would be undefined)
       std::memcpy(&a.buildQuality, &q, sizeof q);
     }},
    {"max_leaf_0", [](auto& a, auto&) { a.maxLeafSize = 0; }},
    {"max_depth_0", [](auto& a, auto&) { a.maxDepth = 0; }},
    {"max_depth_too_small", [](auto& a, auto&) { a.maxDepth = 3, a.maxLeafSize = 1; }},
    {"min_leaf_above_max_leaf", [](auto& a, auto&) { a.minLeafSize = 16; }},
    {"branching_0", [](auto& a, auto&) { a.maxBranchingFactor = 0; }},
    {"branching_1", [](auto& a, auto&) { a.maxBranchingFactor = 1; }},
    {"branching_9", [](auto& a, auto&) { a.maxBranchingFactor = 9; }},
    {"branching_16", [](auto& a, auto&) { a.maxBranchingFactor = 16; }},
    {"branching_17", [](auto& a, auto&) { a.maxBranchingFactor = 17; }},
    {"branching_64", [](auto& a, auto&) { a.maxBranchingFactor = 64; }},
    {"byte_size_larger", [](auto& a, auto&) { a.byteSize = 4096; }},
    {"byte_size_0", [](auto& a, auto&) { a.byteSize = 0; }},  // Embree 3 never reads byteSize
    {"byte_size_16", [](auto& a, auto&) { a.byteSize = 16; }},
    {"no_primitives_at_all", [](auto& a, auto&) { a.primitiveCount = 0; }},
    {"max_leaf_above_32", [](auto& a, auto&) { a.maxLeafSize = 64; }},
};

class SameErrorAsEmbree : public testing::TestWithParam<Case> {};

// kmbvh's LOW too, whose builder is another (LBVH; plugin/README.md, "Build quality"), against
// Embree's MEDIUM: Embree's own LOW builder crashes on branching factors above 8.
TEST_P(SameErrorAsEmbree, Build) {
  const Outcome embree = build_with(app::embree_api(), GetParam().mutate);
  for (const RTCBuildQuality quality : {RTC_BUILD_QUALITY_MEDIUM, RTC_BUILD_QUALITY_LOW})
    EXPECT_EQ(build_with(app::kmbvh_api(), GetParam().mutate, quality), embree) << "quality " << quality;
}

INSTANTIATE_TEST_SUITE_P(Cases, SameErrorAsEmbree, testing::ValuesIn(kSameAsEmbree),
                         [](const auto& info) { return std::string(info.param.name); });

// Cases Embree crashes or asserts on (Embree 3.13.5, Debian): kmbvh reports them.
const Case kEmbreeCrashes[] = {
    {"null_primitives", [](auto& a, auto&) { a.primitives = nullptr; }},
    {"nan_box", [](auto&, auto& p) { p[3].lower_y = NAN; }},
    {"infinite_box", [](auto&, auto& p) { p[7].upper_z = INFINITY; }},
    {"inverted_box", [](auto&, auto& p) { p[5].lower_x = p[5].upper_x + 1; }},
    {"nan_traversal_cost", [](auto& a, auto&) { a.traversalCost = NAN; }},
    {"negative_intersection_cost", [](auto& a, auto&) { a.intersectionCost = -1; }},
};

class EmbreeCrashesKmbvhReports : public testing::TestWithParam<Case> {};

TEST_P(EmbreeCrashesKmbvhReports, Build) {
  Outcome expected;
  expected.device_error = RTC_ERROR_INVALID_ARGUMENT;
  expected.callbacks = {RTC_ERROR_INVALID_ARGUMENT};
  for (const RTCBuildQuality quality : {RTC_BUILD_QUALITY_MEDIUM, RTC_BUILD_QUALITY_LOW})
    EXPECT_EQ(build_with(app::kmbvh_api(), GetParam().mutate, quality), expected) << "quality " << quality;
}

INSTANTIATE_TEST_SUITE_P(Cases, EmbreeCrashesKmbvhReports, testing::ValuesIn(kEmbreeCrashes),
                         [](const auto& info) { return std::string(info.param.name); });

// Null handles: reported without a device, as Embree does.
TEST(BuilderApiErrors, NullHandles) {
  EXPECT_EQ(kmbvhNewBVH(nullptr), nullptr);
  EXPECT_EQ(rtcGetDeviceError(nullptr), RTC_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(rtcNewBVH(nullptr), nullptr);  // Embree's own answer, for comparison
  EXPECT_EQ(rtcGetDeviceError(nullptr), RTC_ERROR_INVALID_ARGUMENT);

  kmbvhRetainBVH(nullptr);
  EXPECT_EQ(rtcGetDeviceError(nullptr), RTC_ERROR_INVALID_ARGUMENT);
  kmbvhReleaseBVH(nullptr);
  EXPECT_EQ(rtcGetDeviceError(nullptr), RTC_ERROR_INVALID_ARGUMENT);

  // Embree crashes on these three.
  EXPECT_EQ(kmbvhBuildBVH(nullptr), nullptr);
  EXPECT_EQ(rtcGetDeviceError(nullptr), RTC_ERROR_INVALID_ARGUMENT);
  RTCBuildArguments a = rtcDefaultBuildArguments();
  EXPECT_EQ(kmbvhBuildBVH(&a), nullptr);  // no BVH
  EXPECT_EQ(rtcGetDeviceError(nullptr), RTC_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(kmbvhThreadLocalAlloc(nullptr, 16, 16), nullptr);
  EXPECT_EQ(rtcGetDeviceError(nullptr), RTC_ERROR_INVALID_ARGUMENT);

  // A handle that is not kmbvh's (an Embree BVH, say) is refused, not misread.
  RTCDevice device = rtcNewDevice(nullptr);
  RTCBVH theirs = rtcNewBVH(device);
  kmbvhRetainBVH(theirs);
  EXPECT_EQ(rtcGetDeviceError(nullptr), RTC_ERROR_INVALID_ARGUMENT);
  rtcReleaseBVH(theirs);
  rtcReleaseDevice(device);
  EXPECT_EQ(rtcGetDeviceError(nullptr), RTC_ERROR_NONE);
}

}  // namespace
}  // namespace kmbvh::test
