// The real Embree behind kmbvh's plug-in: its functions looked up by name with
// dlsym(RTLD_NEXT), i.e. the next definition after the library doing the lookup, which is
// libembree3 whether kmbvh was linked in front of it or preloaded. Every call that kmbvh
// does not answer itself goes there.
#pragma once

namespace kmbvh::plugin {

// The address of Embree's own `name`. Aborts with a message naming the function when
// libembree3 is not loaded (an application that uses Embree always has it).
void* real_embree_symbol(const char* name);

// real_embree<decltype(&rtcIntersect1)>("rtcIntersect1"), looked up once per call site
// through the static in REAL_EMBREE below.
template <typename F>
F real_embree(const char* name) {
  return reinterpret_cast<F>(real_embree_symbol(name));
}

}  // namespace kmbvh::plugin

// Embree's own definition of `fn`, looked up on first use.
#define KMBVH_REAL_EMBREE(fn)                                                                      \
  ([]() {                                                                                          \
    static const auto real = ::kmbvh::plugin::real_embree<decltype(&fn)>(#fn);                   \
    return real;                                                                                   \
  }())
