#include "temporal/core/isa.h"

#include <atomic>
#include <cstdlib>
#include <string>

namespace temporal::isa {
namespace {

struct Choice {
  Level level;
  std::string note;
};

Level highest_supported() {
  if (!TEMPORAL_ISA_DISPATCH) return Level::Native;
  return supported(Level::V4) ? Level::V4 : supported(Level::V3) ? Level::V3 : Level::V2;
}

// TEMPORAL_ISA, read once (the kernels' first call).
const Choice& initial() {
  static const Choice choice = [] {
    Choice c{highest_supported(), {}};
    const char* env = std::getenv("TEMPORAL_ISA");
    if (!env || !*env) return c;
    const std::string want = env;
    if (!TEMPORAL_ISA_DISPATCH) {
      c.note = "TEMPORAL_ISA=" + want + " ignored: this build has one kernel copy (TEMPORAL_NATIVE=ON or not x86-64)";
      return c;
    }
    const Level levels[3] = {Level::V2, Level::V3, Level::V4};
    for (Level l : levels)
      if (want == name(l)) {
        if (supported(l)) c.level = l;
        else c.note = "TEMPORAL_ISA=" + want + ": this CPU cannot run it, using " + std::string(name(c.level));
        return c;
      }
    c.note = "TEMPORAL_ISA=" + want + " is not v2, v3 or v4; using " + std::string(name(c.level));
    return c;
  }();
  return choice;
}

// The level in force; -1 until the first active() reads the environment.
std::atomic<int> current{-1};

}  // namespace

bool dispatching() { return TEMPORAL_ISA_DISPATCH != 0; }

bool supported(Level level) {
#if TEMPORAL_ISA_DISPATCH
  // __builtin_cpu_supports also checks (XGETBV) that the OS saves the AVX / AVX-512 registers.
  switch (level) {
    case Level::V2: return true;  // the baseline: the program would not have started without it
    case Level::V3:
      return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma") && __builtin_cpu_supports("bmi") &&
             __builtin_cpu_supports("bmi2") && __builtin_cpu_supports("popcnt");
    case Level::V4:
      return supported(Level::V3) && __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512bw") &&
             __builtin_cpu_supports("avx512cd") && __builtin_cpu_supports("avx512dq") &&
             __builtin_cpu_supports("avx512vl");
    case Level::Native: return false;
  }
  return false;
#else
  return level == Level::Native;
#endif
}

Level active() {
  int v = current.load(std::memory_order_relaxed);
  if (v < 0) {
    int expected = -1;
    current.compare_exchange_strong(expected, int(initial().level));
    v = current.load(std::memory_order_relaxed);
  }
  return Level(v);
}

std::string_view environment_note() { return initial().note; }

std::string_view name(Level level) {
  switch (level) {
    case Level::V2: return "v2";
    case Level::V3: return "v3";
    case Level::V4: return "v4";
    case Level::Native: return "native";
  }
  return "?";
}

ScopedLevel::ScopedLevel(Level level) : previous_(active()) {
  if (dispatching() && supported(level)) current.store(int(level));
}

ScopedLevel::~ScopedLevel() { current.store(int(previous_)); }

}  // namespace temporal::isa
