// Embree's triangle meshes as kmbvh's input: the vertex and index buffers an application
// handed to Embree (rtcSetSharedGeometryBuffer, rtcSetNewGeometryBuffer,
// rtcSetGeometryBuffer), read with their byte offset, stride and format, flattened into
// one TriangleScene. Each triangle keeps the id Embree reports for it: {geomID, primID}.
#pragma once

#include <embree3/rtcore.h>

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <vector>

#include "adapters/triangles/triangle_scene.h"
#include "cuda/core/primitive_set.h"

namespace kmbvh {

// One buffer as Embree sees it: `data` already includes the byte offset.
struct EmbreeBufferView {
  const void* data = nullptr;
  RTCFormat format = RTC_FORMAT_UNDEFINED;
  size_t byte_stride = 0;
  size_t count = 0;
};

struct EmbreeTriangleMesh {
  uint32_t geom_id = 0;
  EmbreeBufferView vertices;  // slot 0 of RTC_BUFFER_TYPE_VERTEX: RTC_FORMAT_FLOAT3
  EmbreeBufferView indices;   // slot 0 of RTC_BUFFER_TYPE_INDEX: RTC_FORMAT_UINT3
};

struct FlattenedMeshes {
  TriangleScene scene;
  std::vector<PrimitiveId> ids;  // ids[t]: Embree's geomID and primID of scene.triangles[t]
  size_t dropped = 0;            // triangles left out, as Embree's commit leaves them out
};

// A mesh kmbvh cannot read the way Embree would (a missing buffer, another format): the
// caller lets Embree answer instead.
class UnsupportedMesh : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Triangles with an index out of range, or a vertex that is not finite or lies beyond
// Embree's range (|x| >= 1.8e18), are dropped, as rtcCommitScene drops them. Throws
// UnsupportedMesh for a mesh kmbvh cannot read. `reuse`: an earlier flattening (the same
// scene's last commit), whose memory this one takes, so that a scene committed again
// writes no fresh pages; `same_as_reused`, where given, then says whether every triangle
// and id came out as they were in it (only vertices moved: a refit may do).
FlattenedMeshes flatten_triangle_meshes(const std::vector<EmbreeTriangleMesh>& meshes,
                                        FlattenedMeshes* reuse = nullptr, bool* same_as_reused = nullptr);

}  // namespace kmbvh
