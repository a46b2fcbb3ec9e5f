// Method parameters (temporal/core/params.h): text forms and range checks.
#include "temporal/core/params.h"

#include "temporal/core/suggest.h"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace temporal {
namespace {

// Numbers for messages: integers without a fraction, others with up to 6 significant digits.
std::string number(double v) {
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  char text[64];
  if (v == std::floor(v) && std::abs(v) < 1e15)
    std::snprintf(text, sizeof text, "%.0f", v);
  else
    std::snprintf(text, sizeof text, "%.6g", v);
  return text;
}

std::string join(const std::vector<std::string>& items) {
  std::string s;
  for (const auto& x : items) {
    if (!s.empty()) s += ", ";
    s += x;
  }
  return s;
}

}  // namespace

std::string param_value_text(const Param& p) {
  return std::visit(
      [&p](auto* v) -> std::string {
        using T = std::remove_pointer_t<decltype(v)>;
        if constexpr (std::is_same_v<T, bool>)
          return *v != p.inverted ? "on" : "off";
        else if constexpr (std::is_same_v<T, std::string>)
          return *v;
        else if constexpr (std::is_same_v<T, std::vector<std::string>>)
          return join(*v);
        else if constexpr (std::is_same_v<T, std::optional<double>> || std::is_same_v<T, std::optional<int>>)
          return *v ? number(double(**v)) : std::string();
        else
          return number(double(*v));
      },
      p.value);
}

std::string param_range_text(const Param& p) {
  if (!p.choices.empty()) return "one of: " + join(p.choices);
  if (std::holds_alternative<bool*>(p.value) || std::holds_alternative<std::string*>(p.value) ||
      std::holds_alternative<std::vector<std::string>*>(p.value))
    return {};
  const bool lo = std::isfinite(p.min), hi = std::isfinite(p.max);
  // Appended piece by piece: `"[" + std::string` trips a false -Wrestrict in GCC 12.
  std::string text;
  if (lo && hi) {
    text.append(p.above_min ? "(" : "[").append(number(p.min)).append(", ").append(number(p.max)).append("]");
  } else if (lo) {
    text.append(p.above_min ? "> " : ">= ").append(number(p.min));
  } else if (hi) {
    text.append("<= ").append(number(p.max));
  }
  return text;
}

namespace {
Status check_choice(const Param& p, const std::string& value) {
  if (p.choices.empty()) return Status::ok();
  for (const auto& c : p.choices)
    if (value == c) return Status::ok();
  return not_one_of(p.flag, value, p.choices);
}
}  // namespace

Status check_param(const Param& p) {
  if (const auto* s = std::get_if<std::string*>(&p.value)) return check_choice(p, **s);
  if (const auto* list = std::get_if<std::vector<std::string>*>(&p.value)) {
    for (const auto& item : **list)
      if (Status st = check_choice(p, item); !st) return st;
    return Status::ok();
  }
  if (std::holds_alternative<bool*>(p.value)) return Status::ok();
  std::optional<double> value = std::visit(
      [](auto* x) -> std::optional<double> {
        using T = std::remove_pointer_t<decltype(x)>;
        if constexpr (std::is_arithmetic_v<T>) return double(*x);
        if constexpr (std::is_same_v<T, std::optional<double>> || std::is_same_v<T, std::optional<int>>)
          return *x ? std::optional<double>(double(**x)) : std::nullopt;
        return 0.0;
      },
      p.value);
  if (!value) return Status::ok();  // an optional number not given
  const double v = *value;
  if (!std::isfinite(v)) return Error::usage(p.flag + " must be a finite number (got " + number(v) + ")");
  if (v < p.min || v > p.max || (p.above_min && v == p.min))
    return Error::usage(p.flag + " " + number(v) + " is out of range: it must be " + param_range_text(p));
  return Status::ok();
}

Status check_params(const ParamList& params) {
  for (const auto& p : params)
    if (Status s = check_param(p); !s) return s;
  return Status::ok();
}

Status apply_args(const ParamList& params, const std::vector<std::string>& args) {
  for (std::size_t i = 0; i < args.size(); ++i) {
    const Param* p = nullptr;
    for (const auto& candidate : params)
      if (candidate.flag == args[i]) p = &candidate;
    if (!p) return Error::usage("unknown parameter '" + args[i] + "'");
    if (auto* b = std::get_if<bool*>(&p->value)) {
      **b = !p->inverted;  // an inverted flag (--no-snap) clears its field
      continue;
    }
    if (i + 1 == args.size()) return Error::usage(p->flag + " needs a value");
    const std::string& text = args[++i];
    if (text.empty()) return Error::usage(p->flag + " needs a value, got an empty one");
    char* end = nullptr;
    errno = 0;
    const double v = std::strtod(text.c_str(), &end);
    const bool number = !text.empty() && end == text.c_str() + text.size() && errno == 0;
    Status status = std::visit(
        [&](auto* field) -> Status {
          using T = std::remove_pointer_t<decltype(field)>;
          if constexpr (std::is_same_v<T, std::string>) {
            *field = text;
          } else if constexpr (std::is_same_v<T, std::vector<std::string>>) {
            if (!p->separator) {
              field->push_back(text);
            } else {
              std::size_t begin = 0;
              for (std::size_t at; (at = text.find(p->separator, begin)) != std::string::npos; begin = at + 1)
                field->push_back(text.substr(begin, at - begin));
              field->push_back(text.substr(begin));
            }
          } else if constexpr (std::is_same_v<T, int> || std::is_same_v<T, std::optional<int>>) {
            if (!number || v != std::floor(v) || std::abs(v) > 2e9)
              return Error::usage(p->flag + " needs an integer (got '" + text + "')");
            *field = int(v);
          } else if constexpr (std::is_same_v<T, std::optional<double>>) {
            if (!number) return Error::usage(p->flag + " needs a number (got '" + text + "')");
            *field = v;
          } else if constexpr (std::is_arithmetic_v<T>) {
            if (!number) return Error::usage(p->flag + " needs a number (got '" + text + "')");
            *field = T(v);
          }
          return Status::ok();
        },
        p->value);
    if (!status) return status;
    if (Status s = check_param(*p); !s) return s;
  }
  return Status::ok();
}

}  // namespace temporal
