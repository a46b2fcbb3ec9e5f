#include "temporal/core/suggest.h"

#include <algorithm>
#include <cctype>

namespace temporal {
namespace {

char lower(char c) { return char(std::tolower(static_cast<unsigned char>(c))); }

// Optimal string alignment distance (Levenshtein plus adjacent transpositions, "phml" -> "phlm" is one edit).
std::size_t edit_distance(std::string_view a, std::string_view b) {
  const std::size_t n = a.size(), m = b.size();
  std::vector<std::size_t> d((n + 1) * (m + 1));
  auto at = [&](std::size_t i, std::size_t j) -> std::size_t& { return d[i * (m + 1) + j]; };
  for (std::size_t i = 0; i <= n; ++i) at(i, 0) = i;
  for (std::size_t j = 0; j <= m; ++j) at(0, j) = j;
  for (std::size_t i = 1; i <= n; ++i)
    for (std::size_t j = 1; j <= m; ++j) {
      const std::size_t cost = lower(a[i - 1]) == lower(b[j - 1]) ? 0 : 1;
      at(i, j) = std::min({at(i - 1, j) + 1, at(i, j - 1) + 1, at(i - 1, j - 1) + cost});
      if (i > 1 && j > 1 && lower(a[i - 1]) == lower(b[j - 2]) && lower(a[i - 2]) == lower(b[j - 1]))
        at(i, j) = std::min(at(i, j), at(i - 2, j - 2) + 1);
    }
  return at(n, m);
}

}  // namespace

std::string closest_name(std::string_view name, const std::vector<std::string>& choices) {
  std::string best;
  std::size_t best_distance = 0;
  for (const std::string& c : choices) {
    const std::size_t d = edit_distance(name, c);
    if (d > std::max<std::size_t>(1, c.size() / 3)) continue;  // not a typo of c
    if (best.empty() || d < best_distance) {
      best = c;
      best_distance = d;
    }
  }
  return best;
}

Error not_one_of(std::string_view flag, std::string_view value, const std::vector<std::string>& choices) {
  std::string list;
  for (const std::string& c : choices) list += (list.empty() ? "" : ", ") + c;
  std::string message = std::string(flag) + " '" + std::string(value) + "' is not one of: " + list;
  if (const std::string near = closest_name(value, choices); !near.empty()) message += " (did you mean '" + near + "'?)";
  return Error::usage(message);
}

}  // namespace temporal
