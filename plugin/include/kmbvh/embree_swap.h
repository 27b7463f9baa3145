// The one-line swap: include this after <embree3/rtcore.h> and the application's calls to
// Embree's five builder functions build with kmbvh instead (link with kmbvh::embree).
// Nothing else changes: the same RTCBuildArguments, callbacks and error handling.
#pragma once

#include "kmbvh/embree.h"

#define rtcNewBVH kmbvhNewBVH
#define rtcBuildBVH kmbvhBuildBVH
#define rtcThreadLocalAlloc kmbvhThreadLocalAlloc
#define rtcRetainBVH kmbvhRetainBVH
#define rtcReleaseBVH kmbvhReleaseBVH
