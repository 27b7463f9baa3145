// Rays recorded by the preload library. First, its A/B mode (KMBVH_AB_REPORT, plugin/README.md):
// every mismatching ray of the report, in full, with the query it was and the two answers
// it got, so that `kmbvh trace SCENE --replay REPORT` can trace it again on the scene the
// report saved beside it (a regression case made from an application's own ray).
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

#include "cuda/traversal/ray.h"

namespace kmbvh {

struct RecordedRay {
  Ray ray;
  Query query = Query::Closest;
  std::string kind;     // the mismatch it was reported as ("distance", ...)
  std::string form;     // the application's query function ("rtcIntersect1", ...)
  std::string scene;    // the scene entry of the report it came from
  std::string scene_file;  // the OBJ the report saved that scene to ("" if none was saved)
  // The answers in the report; a closest hit names its triangle's position in the saved
  // scene (primID), geomID 0.
  Hit kmbvh, embree;
};

class RayFileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Every first_mismatches ray of every scene and form of the report. Throws RayFileError
// naming the file and what is wrong with it.
std::vector<RecordedRay> read_recorded_rays(const std::string& path);

// The queries an application sent to one scene, recorded by the preload library
// (KMBVH_RECORD_RAYS, plugin/README.md), so that `kmbvh trace SCENE --rays-file FILE` times
// kmbvh against Embree on the application's own rays, away from the application. The file:
// kAppRaysMagic, then one AppRayRecord per query in the order the application sent them
// (several threads' interleaved), native byte order.
constexpr char kAppRaysMagic[8] = {'K', 'M', 'B', 'V', 'H', 'R', 'A', '1'};
struct AppRayRecord {
  float org[3], dir[3], tnear, tfar;
  uint32_t query;  // 0: closest hit (rtcIntersect*), 1: occlusion (rtcOccluded*)
};
static_assert(sizeof(AppRayRecord) == 36, "the record is the file format");

struct AppRays {
  std::vector<Ray> closest, occlusion;
  std::vector<Query> order;  // the kept queries' kinds in the file's order (the application's)
};
// At most `limit` rays of each query, the first ones. Throws RayFileError naming the file
// and what is wrong with it.
AppRays read_app_rays(const std::string& path, size_t limit);

}  // namespace kmbvh
