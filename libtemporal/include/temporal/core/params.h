// Parameters of a method, described once: the library's option structs hold the defaults, and each method lists
// its parameters as Param entries that point at those fields. Tools bind the list to their command line (flag,
// help, default printed from the field, valid range); the benchmark, the golden tests and the pipelines read the
// same list. So a default is written in exactly one place, and a range check cannot be forgotten.
#pragma once

#include "temporal/core/error.h"

#include <limits>
#include <optional>
#include <string>
#include <variant>
#include <vector>

namespace temporal {

// One parameter: the command-line flag, a help line (what it is, the paper's name and equation), the field it
// sets, and its valid range. Floating-point values must be finite and inside [min, max]; integers inside
// [min, max]; strings one of `choices` (when given). Every floating-point option of the tools has a finite
// range that keeps its arithmetic from overflowing or underflowing (issue 26: `--ppd 1e-40` inside [0, 10000]
// made fps / ppd infinite); a value that means "off / derive it" (0) outside that range sets `or_zero`. Optional numbers (a threshold that is off until given) are
// checked the same way once set; a list takes the option again for each value (or `separator`-separated
// values) and checks each against `choices`.
using ParamValue = std::variant<float*, double*, int*, bool*, std::string*, std::optional<double>*,
                                std::optional<int>*, std::vector<std::string>*>;
struct Param {
  std::string flag;  // "--sigma-normal"; a name without a leading '-' is a positional argument ("tests")
  std::string help;  // "sigma_n of the normal weight (seed 000 eq. 2)"
  ParamValue value;
  double min = -std::numeric_limits<double>::infinity();
  double max = std::numeric_limits<double>::infinity();
  std::vector<std::string> choices = {};  // (a default, so designated initializers may leave it out)
  bool above_min = false;  // the value must be strictly greater than min ("> 0")
  // A flag that turns a default-on feature off: giving it sets the bool field to false (`--no-snap` for
  // `GridOptions::snap`), so the option struct keeps its positive-sense field and its default.
  bool inverted = false;
  // The --help section the option is listed under (a method's name: "herzog"); empty: the one add_params names,
  // else the tool's general options.
  std::string group = {};
  char separator = 0;                  // a list: each value is split at this character ("a,b" for --names)
  std::vector<std::string> excludes = {};  // flags that cannot be given together with this one
  // 0 is also valid (an "off" or "derive it" value) although it lies outside [min, max]: `--ppd` is 0 (derived
  // from the screen) or in [0.01, 10000], not 1e-40.
  bool or_zero = false;

  // Shorthands for the common ranges.
  static Param real(std::string flag, std::string help, float* v, double lo, double hi) {
    return {std::move(flag), std::move(help), v, lo, hi, {}};
  }
  static Param real(std::string flag, std::string help, double* v, double lo, double hi) {
    return {std::move(flag), std::move(help), v, lo, hi, {}};
  }
  // A value in [lo, hi], or 0 (off / derived): see `or_zero`.
  static Param real_or_zero(std::string flag, std::string help, float* v, double lo, double hi) {
    Param p{std::move(flag), std::move(help), v, lo, hi, {}};
    p.or_zero = true;
    return p;
  }
  // A value strictly above `lo` (e.g. a positive scale: > 0).
  static Param positive(std::string flag, std::string help, float* v, double lo = 0.0,
                        double hi = std::numeric_limits<double>::infinity()) {
    Param p{std::move(flag), std::move(help), v, lo, hi, {}};
    p.above_min = true;
    return p;
  }
  static Param positive(std::string flag, std::string help, double* v, double lo = 0.0,
                        double hi = std::numeric_limits<double>::infinity()) {
    Param p{std::move(flag), std::move(help), v, lo, hi, {}};
    p.above_min = true;
    return p;
  }
  static Param integer(std::string flag, std::string help, int* v, int lo, int hi) {
    return {std::move(flag), std::move(help), v, double(lo), double(hi), {}};
  }
  static Param flag_on(std::string flag, std::string help, bool* v) { return {std::move(flag), std::move(help), v, 0, 1, {}}; }
  static Param flag_off(std::string flag, std::string help, bool* v) {
    Param p{std::move(flag), std::move(help), v, 0, 1, {}};
    p.inverted = true;
    return p;
  }
  static Param choice(std::string flag, std::string help, std::string* v, std::vector<std::string> options) {
    return {std::move(flag), std::move(help), v, 0, 0, std::move(options)};
  }
  static Param text(std::string flag, std::string help, std::string* v) {
    return {std::move(flag), std::move(help), v, -std::numeric_limits<double>::infinity(),
            std::numeric_limits<double>::infinity(), {}};
  }
  // Text values, one per occurrence or per `separator`-separated item.
  static Param list(std::string flag, std::string help, std::vector<std::string>* v, char separator = 0) {
    Param p{std::move(flag), std::move(help), v};
    p.separator = separator;
    return p;
  }
  // A number that is unset until given (no default), checked against [lo, hi] when set.
  static Param optional(std::string flag, std::string help, std::optional<double>* v,
                        double lo = -std::numeric_limits<double>::infinity(),
                        double hi = std::numeric_limits<double>::infinity()) {
    return {std::move(flag), std::move(help), v, lo, hi, {}};
  }
  static Param optional(std::string flag, std::string help, std::optional<int>* v,
                        double lo = -std::numeric_limits<double>::infinity(),
                        double hi = std::numeric_limits<double>::infinity()) {
    return {std::move(flag), std::move(help), v, lo, hi, {}};
  }
};
using ParamList = std::vector<Param>;

// The current value as text (the default, before parsing): "0.2", "4", "on", "herzog". A flag reads "on" when it is
// in effect (an inverted flag: when its field is false); an unset optional number ""; a list its values joined with
// ", ".
std::string param_value_text(const Param& param);
// The valid range as text: "[0, 1]", "> 0", "0 or [0.01, 10000]", "one of: cache, refresh"; empty when unbounded.
std::string param_range_text(const Param& param);
// Usage error unless the current value is valid: finite, inside the range, one of the choices
// ("--flip: 'yes' is not one of off, ldr, hdr").
Status check_param(const Param& param);
// check_param for every entry (the first failure).
Status check_params(const ParamList& params);
// True for a number parameter that holds a floating-point value (float, double, optional<double>) and has a finite
// range on both sides: what every floating-point option of the tools must have (the tools refuse to start
// otherwise, so a forgotten range fails every test of the tool).
bool has_finite_range(const Param& param);

// Sets parameters from command-line style arguments, e.g. {"--mode", "refresh", "--lagged-wf"}: a flag (bool)
// takes no value, every other parameter the next argument; each value is range-checked. For the named variants
// of a method (benchmarks, pipelines, tests) written the way a user writes them. Usage error for an unknown flag,
// a missing or malformed value, or a value out of range.
Status apply_args(const ParamList& params, const std::vector<std::string>& args);

}  // namespace temporal
