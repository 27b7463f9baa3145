#include "kmbvh.h"

namespace kmbvh {

const char* library_version() { return KMBVH_VERSION; }

}  // namespace kmbvh
