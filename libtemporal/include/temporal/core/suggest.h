// The one wording of "that name is not one of the choices" (a --method, a choice parameter), with a suggestion
// when a choice is close to what was typed ("herzg" -> "herzog"). Every tool and stage says it the same way.
#pragma once

#include "temporal/core/error.h"

#include <string>
#include <string_view>
#include <vector>

namespace temporal {

// The choice closest to `name` by edit distance (insertions, deletions, substitutions and transpositions of
// adjacent characters, case ignored), when it is close enough to be a typo: at most one edit per three characters
// of the choice (at least one). Empty when none is.
std::string closest_name(std::string_view name, const std::vector<std::string>& choices);

// Usage error "FLAG 'VALUE' is not one of: A, B, C" followed by " (did you mean 'B'?)" when closest_name finds one.
Error not_one_of(std::string_view flag, std::string_view value, const std::vector<std::string>& choices);

}  // namespace temporal
