#include "temporal/core/method.h"

namespace temporal {

MethodOptionSet::MethodOptionSet(const MethodOptionSet& other) { *this = other; }
MethodOptionSet& MethodOptionSet::operator=(const MethodOptionSet& other) {
  if (this == &other) return *this;
  entries_.clear();
  for (const auto& [name, options] : other.entries_) entries_.emplace_back(name, options->clone());
  return *this;
}
MethodOptionSet::~MethodOptionSet() = default;

void MethodOptionSet::add(std::string name, std::unique_ptr<MethodOptions> options) {
  entries_.emplace_back(std::move(name), std::move(options));
}

MethodOptions* MethodOptionSet::find(std::string_view name) {
  for (auto& [n, options] : entries_)
    if (n == name) return options.get();
  return nullptr;
}
const MethodOptions* MethodOptionSet::find(std::string_view name) const {
  return const_cast<MethodOptionSet*>(this)->find(name);
}

}  // namespace temporal
