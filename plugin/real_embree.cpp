#include "real_embree.h"

#include <dlfcn.h>

#include <cstdio>
#include <cstdlib>

namespace kmbvh::plugin {

void* real_embree_symbol(const char* name) {
  void* f = dlsym(RTLD_NEXT, name);
  if (!f) {
    // Loaded by dlopen() into a process that has not loaded Embree yet: ask for it by name.
    if (void* lib = dlopen("libembree3.so.3", RTLD_NOW | RTLD_GLOBAL)) f = dlsym(lib, name);
  }
  if (!f) {
    std::fprintf(stderr, "kmbvh: Embree's %s was not found (is libembree3 loaded?): %s\n", name, dlerror());
    std::abort();
  }
  return f;
}

}  // namespace kmbvh::plugin
