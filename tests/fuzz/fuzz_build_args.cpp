// libFuzzer target: the plug-in's argument handling. The input chooses every field of
// RTCBuildArguments (odd qualities, branching factors, leaf sizes, depths, costs, byte
// sizes, missing callbacks, a progress callback that cancels) and the primitives' boxes
// (NaN, infinities, inverted, huge); kmbvhBuildBVH must then either return a tree that is
// valid for those arguments (tests/plugin/app_tree_check.h) with no error, or return null
// with an Embree error reported. Never a crash, a hang or a wrong tree.
#include <fuzzer/FuzzedDataProvider.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <vector>

#include "tests/plugin/app_tree_check.h"

namespace {

float any_float(FuzzedDataProvider& in) {
  static const float special[] = {0.0f, -0.0f, 1.0f, -1.0f, 1e-30f, 1e30f, 3.4e38f,
                                  std::numeric_limits<float>::infinity(),
                                  -std::numeric_limits<float>::infinity(),
                                  std::numeric_limits<float>::quiet_NaN()};
  if (in.ConsumeBool()) return in.PickValueInArray(special);
  return in.ConsumeFloatingPointInRange<float>(-1e6f, 1e6f);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static RTCDevice device = rtcNewDevice(nullptr);
  static const app::BuilderApi api = app::kmbvh_api();
  FuzzedDataProvider in(data, size);

  const size_t count = in.ConsumeIntegralInRange<size_t>(0, 3000);
  std::vector<RTCBuildPrimitive> prims(count + 8);
  const bool wild = in.ConsumeBool();  // otherwise well-formed boxes
  for (size_t i = 0; i < count; ++i) {
    RTCBuildPrimitive& p = prims[i];
    if (wild) {
      p.lower_x = any_float(in), p.lower_y = any_float(in), p.lower_z = any_float(in);
      p.upper_x = any_float(in), p.upper_y = any_float(in), p.upper_z = any_float(in);
    } else {
      p.lower_x = in.ConsumeFloatingPointInRange<float>(-100, 100);
      p.lower_y = in.ConsumeFloatingPointInRange<float>(-100, 100);
      p.lower_z = in.ConsumeFloatingPointInRange<float>(-100, 100);
      p.upper_x = p.lower_x + in.ConsumeFloatingPointInRange<float>(0, 10);
      p.upper_y = p.lower_y + in.ConsumeFloatingPointInRange<float>(0, 10);
      p.upper_z = p.lower_z + in.ConsumeFloatingPointInRange<float>(0, 10);
    }
    p.geomID = 0;
    p.primID = uint32_t(i);
  }
  const std::vector<RTCBuildPrimitive> input(prims.begin(), prims.begin() + count);

  RTCBVH bvh = api.new_bvh(device);
  app::BuildContext ctx{&api};
  RTCBuildArguments a = app::build_arguments(bvh, prims.data(), count, &ctx);
  const int quality = in.ConsumeIntegralInRange<int>(-1, 4);
  std::memcpy(&a.buildQuality, &quality, sizeof quality);
  a.maxBranchingFactor = in.ConsumeIntegralInRange<unsigned>(0, 20);
  a.maxDepth = in.ConsumeIntegralInRange<unsigned>(0, 80);
  a.minLeafSize = in.ConsumeIntegralInRange<unsigned>(0, 40);
  a.maxLeafSize = in.ConsumeIntegralInRange<unsigned>(0, 40);
  a.traversalCost = in.ConsumeBool() ? any_float(in) : 1.0f;
  a.intersectionCost = in.ConsumeBool() ? any_float(in) : 1.0f;
  a.primitiveArrayCapacity = count + 8 - in.ConsumeIntegralInRange<size_t>(0, 10);
  static const size_t byte_sizes[] = {sizeof(RTCBuildArguments), 0, 16, 64};
  a.byteSize = in.PickValueInArray(byte_sizes);
  if (in.ConsumeIntegralInRange(0, 15) == 0) a.createNode = nullptr;
  if (in.ConsumeIntegralInRange(0, 15) == 0) a.createLeaf = nullptr;
  static double stop_at;
  stop_at = in.ConsumeBool() ? 2.0 : in.ConsumeProbability<double>();
  a.buildProgress = [](void*, double done) { return done < stop_at; };

  rtcGetDeviceError(device);  // clear
  rtcGetDeviceError(nullptr);
  const void* root = api.build(&a);
  const RTCError device_error = rtcGetDeviceError(device), thread_error = rtcGetDeviceError(nullptr);
  if (root && count == 0) {
    if (device_error != RTC_ERROR_NONE || thread_error != RTC_ERROR_NONE) std::abort();  // one empty leaf, as Embree
  } else if (root) {
    if (device_error != RTC_ERROR_NONE || thread_error != RTC_ERROR_NONE) std::abort();  // a tree and an error
    const kmbvh::test::AppTreeReport report =
        kmbvh::test::check_app_tree(static_cast<const app::Node*>(root), input, a);
    if (!report.ok()) {
      std::fprintf(stderr, "invalid tree: %s\n", report.problem.c_str());
      std::abort();
    }
  } else if (device_error == RTC_ERROR_NONE && thread_error == RTC_ERROR_NONE) {
    std::abort();  // no tree and no error
  }
  api.release(bvh);
  return 0;
}
