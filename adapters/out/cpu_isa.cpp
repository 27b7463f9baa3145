#include "cpu_isa.h"

#include <cstdlib>
#include <stdexcept>

namespace kmbvh {

const char* to_string(CpuIsa isa) {
  switch (isa) {
    case CpuIsa::Sse42: return "sse4.2";
    case CpuIsa::Avx2: return "avx2";
    case CpuIsa::Avx512: return "avx512";
  }
  return "?";
}

bool cpu_runs(CpuIsa isa) {
  __builtin_cpu_init();
  // The features each variant is compiled with (trace_wide.cpp's target regions); libgcc
  // and compiler-rt report AVX and AVX-512 only where the operating system saves their
  // registers.
  const bool sse42 = __builtin_cpu_supports("sse4.2") && __builtin_cpu_supports("popcnt");
  const bool avx2 = sse42 && __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma") &&
                    __builtin_cpu_supports("bmi") && __builtin_cpu_supports("bmi2");
  switch (isa) {
    case CpuIsa::Sse42: return sse42;
    case CpuIsa::Avx2: return avx2;
    case CpuIsa::Avx512:
      return avx2 && __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") &&
             __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512dq") &&
             __builtin_cpu_supports("avx512cd");
  }
  return false;
}

std::vector<CpuIsa> cpu_isas() {
  std::vector<CpuIsa> out;
  for (CpuIsa isa : {CpuIsa::Sse42, CpuIsa::Avx2, CpuIsa::Avx512})
    if (cpu_runs(isa)) out.push_back(isa);
  return out;
}

CpuIsa choose_isa(const char* requested) {
  const std::vector<CpuIsa> runs = cpu_isas();
  std::string list;
  for (CpuIsa isa : runs) list += std::string(list.empty() ? "" : ", ") + to_string(isa);
  if (!requested || !*requested) {
    if (runs.empty()) throw std::invalid_argument("this CPU has no SSE4.2, the least kmbvh's traversal needs");
    return runs.back();
  }
  for (CpuIsa isa : {CpuIsa::Sse42, CpuIsa::Avx2, CpuIsa::Avx512}) {
    if (std::string(requested) != to_string(isa)) continue;
    if (!cpu_runs(isa))
      throw std::invalid_argument("KMBVH_ISA=" + std::string(requested) + ": this CPU does not run it (it runs " +
                                  (list.empty() ? "none" : list) + ")");
    return isa;
  }
  throw std::invalid_argument("KMBVH_ISA=" + std::string(requested) + ": not an instruction set (sse4.2, avx2 or avx512)");
}

CpuIsa traversal_isa() {
  static const CpuIsa isa = choose_isa(std::getenv("KMBVH_ISA"));
  return isa;
}

}  // namespace kmbvh
