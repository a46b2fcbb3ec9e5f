// The .usda text parser: a recursive-descent reader of the Sdf text format (the grammar of OpenUSD's
// textFileFormat.yy, reduced to what scene replay needs; docs/usd.md) into the specs of usd_layer.h.
// Every error is `file:line:column: what is wrong`; nothing here can crash on malformed input (the fuzz
// target tests/fuzz/usda_fuzz.cpp runs this file under AddressSanitizer and UBSan).
#include "usd_layer.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>

namespace temporal::usd {

const Value* Value::find(std::string_view key) const {
  if (kind != Kind::Dict || !dict) return nullptr;
  for (const auto& [k, v] : *dict)
    if (k == key) return &v;
  return nullptr;
}

const PrimSpec* VariantSetSpec::find(std::string_view variant) const {
  for (const auto& v : variants)
    if (v.name == variant) return v.prim.get();
  return nullptr;
}

const PrimSpec* PrimSpec::child(std::string_view n) const {
  auto it = child_index.find(std::string(n));
  return it == child_index.end() ? nullptr : children[it->second].get();
}

const PropertySpec* PrimSpec::property(std::string_view n) const {
  auto it = property_index.find(std::string(n));
  return it == property_index.end() ? nullptr : &properties[it->second];
}

const VariantSetSpec* PrimSpec::variant_set(std::string_view n) const {
  for (const auto& s : variant_sets)
    if (s.name == n) return &s;
  return nullptr;
}

const std::string* PrimSpec::variant_selection(std::string_view set) const {
  for (const auto& [k, v] : variant_selections)
    if (k == set) return &v;
  return nullptr;
}

const Value* PrimSpec::meta(std::string_view key) const {
  for (const auto& [k, v] : metadata)
    if (k == key) return &v;
  return nullptr;
}

bool Layer::has(std::string_view key) const {
  return std::any_of(metadata.begin(), metadata.end(), [&](const auto& kv) { return kv.first == key; });
}

double Layer::number(std::string_view key, double fallback) const {
  for (const auto& [k, v] : metadata)
    if (k == key && v.kind == Value::Kind::Number && v.numbers.size() == 1) return v.numbers[0];
  return fallback;
}

std::string Layer::token(std::string_view key, const std::string& fallback) const {
  for (const auto& [k, v] : metadata)
    if (k == key && v.kind == Value::Kind::String && v.text.size() == 1) return v.text[0];
  return fallback;
}

const PrimSpec* Layer::prim_at(std::string_view path) const { return descend_path(&root, path); }

std::string absolute_path(std::string_view prim_path, std::string_view target) {
  if (!target.empty() && target[0] == '/') return std::string(target);
  std::string base(prim_path);
  if (!target.empty() && target[0] == '.' && (target.size() == 1 || target[1] != '.')) {
    // ".prop": a property of the prim itself.
    return base + std::string(target);
  }
  std::size_t i = 0;
  while (i < target.size()) {
    std::size_t j = target.find('/', i);
    if (j == std::string_view::npos) j = target.size();
    const std::string_view part = target.substr(i, j - i);
    if (part == "..") {
      const std::size_t slash = base.rfind('/');
      base = slash == 0 || slash == std::string::npos ? std::string("/") : base.substr(0, slash);
    } else if (!part.empty() && part != ".") {
      if (base.empty() || base.back() != '/') base += '/';
      base += part;
    }
    i = j + 1;
  }
  return base.empty() ? std::string("/") : base;
}

namespace {

constexpr int kMaxDepth = 128;  // nesting of prims, variants, tuples and dictionaries

bool ident_start(char c) { return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || c == '_'; }
bool ident_char(char c) { return ident_start(c) || (c >= '0' && c <= '9'); }

struct TypeInfo {
  Value::Kind kind = Value::Kind::Number;
  int tuple = 1;
  bool known = true;
};

// The value class and tuple size of a declared attribute type (Sdf value type names).
TypeInfo type_info(std::string_view t) {
  if (t == "string" || t == "token" || t == "pathExpression") return {Value::Kind::String, 1};
  if (t == "asset") return {Value::Kind::Asset, 1};
  if (t == "dictionary") return {Value::Kind::Dict, 1};
  if (t == "opaque" || t == "group") return {Value::Kind::Empty, 1};
  if (t == "matrix2d") return {Value::Kind::Number, 4};
  if (t == "matrix3d") return {Value::Kind::Number, 9};
  if (t == "matrix4d" || t == "frame4d") return {Value::Kind::Number, 16};
  if (t == "quatf" || t == "quatd" || t == "quath") return {Value::Kind::Number, 4};
  static const char* const scalars[] = {"bool", "uchar", "int", "uint", "int64", "uint64", "half", "float", "double", "timecode"};
  for (const char* s : scalars)
    if (t == s) return {Value::Kind::Number, 1};
  static const char* const prefixes[] = {"int", "half", "float", "double", "point", "normal", "vector", "color", "texCoord"};
  for (const char* p : prefixes) {
    const std::string_view ps(p);
    if (t.size() < ps.size() + 1 || t.substr(0, ps.size()) != ps) continue;
    const char n = t[ps.size()];
    const std::string_view rest = t.substr(ps.size() + 1);
    if (n < '2' || n > '4') continue;
    const bool plain = ps == "int" || ps == "half" || ps == "float" || ps == "double";
    if ((plain && rest.empty()) || (!plain && (rest == "f" || rest == "d" || rest == "h"))) return {Value::Kind::Number, n - '0'};
  }
  return {Value::Kind::Empty, 1, false};
}

class Parser {
 public:
  Parser(std::string_view text, const std::string& file) : s_(text), file_(file) {
    dir_ = std::filesystem::path(file).parent_path().string();
  }

  Expected<std::unique_ptr<Layer>> parse() {
    auto layer = std::make_unique<Layer>();
    layer->path = file_;
    layer->root.path = "/";
    if (Status st = header(); !st) return st.error();
    if (Status st = layer_body(*layer); !st) return st.error();
    return layer;
  }

 private:
  // ---- characters, whitespace, positions ------------------------------------------------------------------

  bool at_end() const { return i_ >= s_.size(); }
  char cur() const { return i_ < s_.size() ? s_[i_] : '\0'; }
  char ahead(std::size_t k) const { return i_ + k < s_.size() ? s_[i_ + k] : '\0'; }

  void newline_at(std::size_t pos) {
    ++line_;
    line_start_ = pos + 1;
  }

  // Skips blanks, newlines and comments (#, //, /* */). Inline check first: most calls find a token at once.
  void ws() {
    if (i_ < s_.size()) {
      const char c = s_[i_];
      if (c != ' ' && c != '\n' && c != '\t' && c != '\r' && c != '#' && c != '/' && c != '\f' && c != '\v') return;
    }
    ws_slow();
  }

  __attribute__((noinline)) void ws_slow() {
    while (i_ < s_.size()) {
      const char c = s_[i_];
      if (c == '\n') {
        newline_at(i_);
        ++i_;
      } else if (c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v') {
        ++i_;
      } else if (c == '#' || (c == '/' && ahead(1) == '/')) {
        while (i_ < s_.size() && s_[i_] != '\n') ++i_;
      } else if (c == '/' && ahead(1) == '*') {
        i_ += 2;
        while (i_ < s_.size() && !(s_[i_] == '*' && ahead(1) == '/')) {
          if (s_[i_] == '\n') newline_at(i_);
          ++i_;
        }
        i_ = std::min(i_ + 2, s_.size());
      } else {
        break;
      }
    }
  }

  int column() const { return int(i_ - line_start_) + 1; }

  // A short description of what comes next, for messages: the next word, number or character.
  std::string found() const {
    if (at_end()) return "the end of the file";
    std::size_t j = i_ + 1;
    if (ident_char(s_[i_]) || s_[i_] == '-' || s_[i_] == '.') {
      while (j < s_.size() && j - i_ < 24 && (ident_char(s_[j]) || s_[j] == '.' || s_[j] == ':')) ++j;
    }
    std::string t;
    for (std::size_t k = i_; k < j; ++k) {
      const auto c = static_cast<unsigned char>(s_[k]);
      t += (c < 32 || c > 126) ? '?' : char(c);
    }
    return "'" + t + "'";
  }

  Error error(const std::string& what) const {
    return Error::input(file_ + ":" + std::to_string(line_) + ":" + std::to_string(column()), what);
  }
  Error error_at(int line, int col, const std::string& what) const {
    return Error::input(file_ + ":" + std::to_string(line) + ":" + std::to_string(col), what);
  }

  bool accept(char c) {
    ws();
    if (cur() != c) return false;
    ++i_;
    return true;
  }

  Status expect(char c, const std::string& context) {
    if (accept(c)) return {};
    return error(std::string("expected '") + c + "' " + context + ", found " + found());
  }
  // The same for a literal context, which costs nothing unless the character is missing.
  Status expect(char c, const char* context) {
    if (accept(c)) return {};
    return error(std::string("expected '") + c + "' " + context + ", found " + found());
  }

  // The next identifier without consuming it ("" when none).
  std::string_view peek_word() {
    ws();
    if (!ident_start(cur())) return {};
    std::size_t j = i_;
    while (j < s_.size() && ident_char(s_[j])) ++j;
    return s_.substr(i_, j - i_);
  }

  bool accept_word(std::string_view w) {
    if (peek_word() != w) return false;
    i_ += w.size();
    return true;
  }

  // A namespaced identifier: name(:name)*.
  Expected<std::string> identifier(const std::string& what) {
    ws();
    if (!ident_start(cur())) return error("expected " + what + ", found " + found());
    const std::size_t start = i_;
    while (i_ < s_.size()) {
      if (ident_char(s_[i_])) {
        ++i_;
      } else if (s_[i_] == ':' && ident_start(ahead(1))) {
        ++i_;
      } else {
        break;
      }
    }
    return std::string(s_.substr(start, i_ - start));
  }

  // ---- literals ----------------------------------------------------------------------------------------------

  Expected<std::string> string_literal() {
    ws();
    const char q = cur();
    if (q != '"' && q != '\'') return error("expected a quoted string, found " + found());
    const bool triple = ahead(1) == q && ahead(2) == q;
    const int line = line_, col = column();
    i_ += triple ? 3 : 1;
    std::string out;
    while (true) {
      if (at_end()) return error_at(line, col, "unterminated string (add the closing " + std::string(triple ? 3 : 1, q) + ")");
      const char c = s_[i_];
      if (triple && c == q && ahead(1) == q && ahead(2) == q) {
        i_ += 3;
        break;
      }
      if (!triple && c == q) {
        ++i_;
        break;
      }
      if (!triple && c == '\n') return error_at(line, col, "unterminated string: a quoted string ends at the end of its line");
      if (c == '\n') newline_at(i_);
      if (c == '\\' && i_ + 1 < s_.size()) {
        const char e = s_[i_ + 1];
        out += e == 'n' ? '\n' : e == 't' ? '\t' : e == 'r' ? '\r' : e == '0' ? '\0' : e;
        if (e == '\n') newline_at(i_ + 1);
        i_ += 2;
        continue;
      }
      out += c;
      ++i_;
    }
    return out;
  }

  // @path@ or @@@path@@@ (the latter may contain '@').
  Expected<std::string> asset_literal() {
    ws();
    if (cur() != '@') return error("expected an asset path (@file@), found " + found());
    const int line = line_, col = column();
    const bool triple = ahead(1) == '@' && ahead(2) == '@';
    i_ += triple ? 3 : 1;
    const std::string_view close = triple ? "@@@" : "@";
    const std::size_t end = s_.find(close, i_);
    const std::size_t nl = s_.find('\n', i_);
    if (end == std::string_view::npos || (nl != std::string_view::npos && nl < end))
      return error_at(line, col, "unterminated asset path (close it with " + std::string(close) + ")");
    std::string out(s_.substr(i_, end - i_));
    i_ = end + close.size();
    return out;
  }

  std::string resolve_asset(const std::string& asset) const {
    if (asset.empty()) return {};
    std::filesystem::path p(asset);
    if (p.is_relative()) p = std::filesystem::path(dir_) / p;
    return p.lexically_normal().string();
  }

  // <path>, made absolute against `prim` (the prim that authors it).
  Expected<std::string> path_literal(const std::string& prim) {
    ws();
    if (cur() != '<') return error("expected a path (<...>), found " + found());
    const int line = line_, col = column();
    const std::size_t end = s_.find('>', i_ + 1);
    const std::size_t nl = s_.find('\n', i_);
    if (end == std::string_view::npos || (nl != std::string_view::npos && nl < end))
      return error_at(line, col, "unterminated path (close it with '>')");
    const std::string_view body = s_.substr(i_ + 1, end - i_ - 1);
    i_ = end + 1;
    if (body.find_first_of(" \t\"'@<{}[]()") != std::string_view::npos)
      return error_at(line, col, "'" + std::string(body) + "' is not a valid path");
    if (body.empty()) return std::string();
    return absolute_path(prim, body);
  }

  // Reads a number at the cursor into v; false, consuming nothing, when there is none. The usual form (at most
  // 19 significant digits and a power of ten within 1e-22..1e22, e.g. every float printed with %.9g) is
  // converted by Clinger's fast path, which is exact there (one correctly rounded product or quotient of two
  // exact doubles); anything else goes to std::from_chars. Numbers are most of a .usda file's bytes, and this
  // halved the parse time of the built-in scenes (tested against from_chars bit for bit).
  bool scan_number(double& v) {
    const char* p = s_.data() + i_;
    const char* const end = s_.data() + s_.size();
    bool negative = false;
    if (p < end && (*p == '-' || *p == '+')) negative = *p++ == '-';
    if (p < end && (*p == 'i' || *p == 'n')) {
      const std::string_view w(p, std::size_t(std::min<std::ptrdiff_t>(3, end - p)));
      if ((w == "inf" || w == "nan") && !(p + 3 < end && ident_char(p[3]))) {
        v = w == "nan" ? std::nan("") : negative ? -HUGE_VAL : HUGE_VAL;
        i_ = std::size_t(p + 3 - s_.data());
        return true;
      }
      return false;
    }
    const char* const digits = p;
    auto digit = [](char c) { return static_cast<unsigned>(c - '0') < 10u; };
    std::uint64_t m = 0;  // wraps past 19 digits, which then go to from_chars
    int exp10 = 0;
    bool any = false;
    while (p < end && *p == '0') ++p, any = true;
    const char* const int_start = p;
    while (p < end && digit(*p)) m = m * 10 + unsigned(*p++ - '0');
    int significant = int(p - int_start);
    any = any || significant > 0;
    if (p < end && *p == '.') {
      ++p;
      if (significant == 0) {
        const char* zeros = p;
        while (p < end && *p == '0') ++p;
        exp10 -= int(p - zeros);
        any = any || p > zeros;
      }
      const char* const frac_start = p;
      while (p < end && digit(*p)) m = m * 10 + unsigned(*p++ - '0');
      const int fraction = int(p - frac_start);
      significant += fraction;
      exp10 -= fraction;
      any = any || fraction > 0;
    }
    const bool exact = significant <= 19;
    if (!any) return false;
    if (p < end && (*p == 'e' || *p == 'E')) {
      const char* q = p + 1;
      const bool eneg = q < end && *q == '-';
      if (q < end && (*q == '-' || *q == '+')) ++q;
      if (q < end && digit(*q)) {  // an 'e' without digits is not part of the number
        int e = 0;
        for (; q < end && digit(*q); ++q) {
          if (e < 100000) e = e * 10 + (*q - '0');
        }
        exp10 += eneg ? -e : e;
        p = q;
      }
    }
    static constexpr double kPow10[] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,  1e8,  1e9,  1e10, 1e11,
                                        1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};
    if (m == 0 && exact) {
      v = negative ? -0.0 : 0.0;
    } else if (exact && m < (std::uint64_t(1) << 53) && exp10 >= -22 && exp10 <= 22) {
      v = exp10 < 0 ? double(m) / kPow10[-exp10] : double(m) * kPow10[exp10];
      if (negative) v = -v;
    } else {
      const auto r = std::from_chars(digits, end, v);
      if (r.ec == std::errc::result_out_of_range) {
        // Beyond double: strtod gives the infinity or the zero the text means.
        v = std::strtod(std::string(digits, r.ptr).c_str(), nullptr);
      } else if (r.ec != std::errc()) {
        return false;
      }
      p = r.ptr;
      if (negative) v = -v;
    }
    i_ = std::size_t(p - s_.data());
    return true;
  }

  Expected<double> number() {
    ws();
    double v = 0.0;
    if (!scan_number(v)) return error("expected a number, found " + found());
    return v;
  }

  bool at_number() {
    ws();
    const char c = cur();
    if ((c >= '0' && c <= '9') || c == '.') return true;
    if (c == '-' || c == '+') {
      const char d = ahead(1);
      return (d >= '0' && d <= '9') || d == '.' || d == 'i' || d == 'n';
    }
    return false;
  }

  // ---- values ------------------------------------------------------------------------------------------------

  // ( n, n, ( n, ... ), ... ): numbers appended flat; returns how many.
  Expected<int> tuple(std::vector<double>& out, int depth) {
    if (depth > kMaxDepth) return error("values nested too deeply");
    if (Status s = expect('(', "to open a tuple"); !s) return s.error();
    int count = 0;
    while (true) {
      if (accept(')')) break;
      if (count > 0) {
        if (!accept(',')) return error("expected ',' or ')' in a tuple, found " + found());
        if (accept(')')) break;  // trailing comma
      }
      ws();
      if (cur() == '(') {
        auto n = tuple(out, depth + 1);
        if (!n) return n.error();
        count += *n;
      } else {
        double v = 0.0;
        if (!scan_number(v)) return error("expected a number, found " + found());
        out.push_back(v);
        ++count;
      }
    }
    if (count == 0) return error("empty tuple");
    return count;
  }

  // One scalar, tuple, string, asset, path or word of an array (or a lone value), appended to `out`.
  Status element(Value& out, const std::string& prim, int depth) {
    ws();
    const char c = cur();
    Value::Kind kind;
    int tup = 1;
    if (c == '(') {
      kind = Value::Kind::Number;
      const std::size_t save = i_, save_size = out.numbers.size(), save_line_start = line_start_;
      const int save_line = line_;
      if (!flat_tuple(out.numbers, tup)) {  // nested tuples (matrices), comments or an error: the general way
        i_ = save;
        line_ = save_line;
        line_start_ = save_line_start;
        out.numbers.resize(save_size);
        auto n = tuple(out.numbers, depth + 1);
        if (!n) return n.error();
        tup = *n;
      }
    } else if (at_number()) {
      kind = Value::Kind::Number;
      double v = 0.0;
      if (!scan_number(v)) return error("expected a number, found " + found());
      out.numbers.push_back(v);
    } else if (c == '"' || c == '\'') {
      kind = Value::Kind::String;
      auto t = string_literal();
      if (!t) return t.error();
      out.text.push_back(std::move(*t));
    } else if (c == '@') {
      kind = Value::Kind::Asset;
      auto t = asset_literal();
      if (!t) return t.error();
      out.resolved.push_back(resolve_asset(*t));
      out.text.push_back(std::move(*t));
    } else if (c == '<') {
      kind = Value::Kind::Path;
      auto t = path_literal(prim);
      if (!t) return t.error();
      out.text.push_back(std::move(*t));
    } else if (ident_start(c)) {
      auto w = identifier("a value");
      if (!w) return w.error();
      if (*w == "true" || *w == "false") {
        kind = Value::Kind::Number;
        out.numbers.push_back(*w == "true" ? 1.0 : 0.0);
      } else {
        kind = Value::Kind::String;  // a bare token (e.g. `permission = public`)
        out.text.push_back(std::move(*w));
      }
    } else {
      return error("expected a value, found " + found());
    }
    if (out.kind == Value::Kind::Empty) {
      out.kind = kind;
      out.tuple = tup;
    } else if (out.kind != kind) {
      return error("an array mixes values of different kinds");
    } else if (out.tuple != tup) {
      return error("an array mixes tuples of " + std::to_string(out.tuple) + " and " + std::to_string(tup) + " values");
    }
    return {};
  }

  // Any value: None, [ elements ], { dictionary }, or one element.
  Status value(Value& out, const std::string& prim, int depth) {
    if (depth > kMaxDepth) return error("values nested too deeply");
    ws();
    out = Value{};
    if (peek_word() == "None") {
      i_ += 4;
      out.kind = Value::Kind::None;
      return {};
    }
    if (cur() == '{') return dictionary(out, prim, depth + 1);
    if (cur() != '[') return element(out, prim, depth);
    ++i_;
    out.array = true;
    if (numeric_array(out)) return {};
    bool first = true;
    while (!accept(']')) {
      if (!first && !accept(',')) return error("expected ',' or ']' in an array, found " + found());
      first = false;
      if (accept(']')) break;  // trailing comma
      if (Status s = element(out, prim, depth + 1); !s) return s;
    }
    return {};
  }

  // The common case of an array of numbers or of flat tuples of numbers, separated by blanks and newlines only,
  // read in one tight loop after the '['. Anything else (comments, nested tuples, strings, an error) restores
  // the cursor and returns false, and the general parser reads the array (and reports what is wrong).
  // Blanks and newlines (no comments), for the fast paths below.
  void blank() {
    while (i_ < s_.size()) {
      const char c = s_[i_];
      if (c == '\n') {
        newline_at(i_);
      } else if (c != ' ' && c != '\t' && c != '\r') {
        return;
      }
      ++i_;
    }
  }

  // "(n, n, ...)" at the cursor: the numbers appended to `out` and their count in n; false (the cursor then
  // somewhere inside) on anything else, for the caller to restore and hand to the general parser.
  bool flat_tuple(std::vector<double>& out, int& n) {
    ++i_;  // '('
    n = 0;
    double v = 0.0;
    while (true) {
      blank();
      if (!scan_number(v)) return false;
      out.push_back(v);
      ++n;
      blank();
      if (i_ >= s_.size()) return false;
      if (s_[i_] == ')') break;
      if (s_[i_] != ',') return false;
      ++i_;
    }
    ++i_;
    return true;
  }

  bool numeric_array(Value& out) {
    const std::size_t save = i_, save_line_start = line_start_;
    const int save_line = line_;
    // Numbers go to a reused scratch buffer first and then into a vector of the exact size: one allocation
    // per array instead of a doubling series (a large part of the time spent on big arrays).
    std::vector<double>& numbers = scratch_;
    numbers.clear();
    auto fail = [&]() {
      i_ = save;
      line_ = save_line;
      line_start_ = save_line_start;
      return false;
    };
    int tuple_size = -1;
    double v = 0.0;
    while (true) {
      blank();
      if (i_ >= s_.size()) return fail();
      if (s_[i_] == ']') break;
      int n = 0;
      if (s_[i_] == '(') {
        if (!flat_tuple(numbers, n)) return fail();
      } else {
        if (!scan_number(v)) return fail();
        numbers.push_back(v);
        n = 1;
      }
      if (tuple_size >= 0 && n != tuple_size) return fail();
      tuple_size = n;
      blank();
      if (i_ >= s_.size()) return fail();
      if (s_[i_] == ']') break;
      if (s_[i_] != ',') return fail();
      ++i_;
    }
    ++i_;  // ']'
    if (tuple_size < 0) return fail();  // [] takes its kind from the declared type
    out.numbers.assign(numbers.begin(), numbers.end());
    out.kind = Value::Kind::Number;
    out.tuple = tuple_size;
    return true;
  }

  // { type name = value ... } (dictionary metadata, `variants = { string set = "v" }`).
  Status dictionary(Value& out, const std::string& prim, int depth) {
    if (Status s = expect('{', "to open a dictionary"); !s) return s;
    auto dict = std::make_shared<Dictionary>();
    while (!accept('}')) {
      if (accept(';') || accept(',')) continue;
      ws();
      if (cur() == '<') {
        // relocates-style `<a>: <b>` entries: read and dropped.
        for (int k = 0; k < 2; ++k) {
          auto p = path_literal(prim);
          if (!p) return p.error();
          if (k == 0 && !accept(':')) return error("expected ':' between two paths, found " + found());
        }
        continue;
      }
      auto type = identifier("a value type in a dictionary");
      if (!type) return type.error();
      if (accept('[')) {
        if (Status s = expect(']', "after '[' in an array type"); !s) return s;
      }
      std::string key;
      ws();
      if (cur() == '"' || cur() == '\'') {
        auto k = string_literal();
        if (!k) return k.error();
        key = std::move(*k);
      } else {
        auto k = identifier("a dictionary key");
        if (!k) return k.error();
        key = std::move(*k);
      }
      if (Status s = expect('=', "after dictionary key '" + key + "'"); !s) return s;
      Value v;
      if (Status s = value(v, prim, depth + 1); !s) return s;
      dict->emplace_back(std::move(key), std::move(v));
    }
    out.kind = Value::Kind::Dict;
    out.dict = std::move(dict);
    return {};
  }

  // Checks a value against its declared type (and gives empty arrays their kind).
  Status check_type(Value& v, const TypeInfo& t, bool array, const std::string& what, int line, int col) {
    if (!t.known || v.kind == Value::Kind::None) return {};
    if (v.kind == Value::Kind::Empty && v.array) {
      v.kind = t.kind;
      v.tuple = t.tuple;
      return {};
    }
    if (t.kind == Value::Kind::Empty) return {};
    if (v.kind != t.kind && !(t.kind == Value::Kind::String && v.kind == Value::Kind::Asset))
      return error_at(line, col, "the value of " + what + " does not match its type");
    if (v.array != array) return error_at(line, col, what + (array ? " is an array type but its value is not an array"
                                                                   : " is not an array type but its value is an array"));
    if (v.kind == Value::Kind::Number && v.tuple != t.tuple)
      return error_at(line, col, what + " needs " + std::to_string(t.tuple) + " numbers per element, the value has " +
                                     std::to_string(v.tuple));
    return {};
  }

  // ---- layer structure ---------------------------------------------------------------------------------------

  Status header() {
    if (s_.substr(0, 3) == "\xEF\xBB\xBF") i_ = 3;
    if (s_.substr(i_, 5) != "#usda") return error("not a text USD layer: the first line must be '#usda 1.0'");
    i_ += 5;
    while (cur() == ' ' || cur() == '\t') ++i_;
    if (cur() != '1') return error("unsupported .usda version (this reader reads '#usda 1.0')");
    while (!at_end() && cur() != '\n') ++i_;
    return {};
  }

  Status layer_offset(LayerOffset& off, const std::string& prim) {
    // ( offset = 1; scale = 2 ), other entries (customData ...) read and dropped.
    if (Status s = expect('(', "to open a layer offset"); !s) return s;
    while (!accept(')')) {
      if (accept(';')) continue;
      auto key = metadata_key("'offset' or 'scale'");
      if (!key) return key.error();
      if (*key == "offset" || *key == "scale") {
        auto v = number();
        if (!v) return v.error();
        (*key == "offset" ? off.offset : off.scale) = *v;
      } else {
        Value ignored;
        if (Status s = value(ignored, prim, 1); !s) return s;
      }
    }
    return {};
  }

  Status layer_body(Layer& layer) {
    ws();
    if (cur() == '(') {
      ++i_;
      if (Status s = layer_metadata(layer); !s) return s;
    }
    while (true) {
      ws();
      if (at_end()) break;
      if (accept(';')) continue;
      if (accept_word("reorder")) {
        if (Status s = skip_reorder(); !s) return s;
        continue;
      }
      if (Status s = prim_statement(layer.root, 0); !s) return s;
    }
    const Value* dp = nullptr;
    for (const auto& [k, v] : layer.metadata)
      if (k == "defaultPrim") dp = &v;
    if (dp && dp->kind == Value::Kind::String && dp->text.size() == 1) layer.default_prim = dp->text[0];
    return {};
  }

  // In a metadata block `( ... )`: skips one ';' separator or one doc string (read and dropped). True when it
  // skipped one (the caller goes on to the next entry), false at an entry; the string's error when it is bad.
  Expected<bool> skip_separator_or_doc() {
    ws();
    if (accept(';')) return true;
    if (cur() == '"' || cur() == '\'') {
      auto doc = string_literal();
      if (!doc) return doc.error();
      return true;
    }
    return false;
  }

  // `key =` of a metadata entry: the key (`what` names it in the error when there is none).
  Expected<std::string> metadata_key(const std::string& what) {
    auto key = identifier(what);
    if (!key) return key.error();
    if (Status s = expect('=', "after '" + *key + "'"); !s) return s.error();
    return key;
  }

  Status layer_metadata(Layer& layer) {
    while (!accept(')')) {
      auto skipped = skip_separator_or_doc();
      if (!skipped) return skipped.error();
      if (*skipped) continue;
      auto key = metadata_key("a layer metadata key");
      if (!key) return key.error();
      if (*key == "subLayers") {
        if (Status s = sublayers(layer); !s) return s;
        continue;
      }
      Value v;
      if (Status s = value(v, "/", 1); !s) return s;
      layer.metadata.emplace_back(std::move(*key), std::move(v));
    }
    return {};
  }

  Status sublayers(Layer& layer) {
    if (Status s = expect('[', "to open the subLayers list"); !s) return s;
    bool first = true;
    while (!accept(']')) {
      if (!first && !accept(',')) return error("expected ',' or ']' in subLayers, found " + found());
      first = false;
      if (accept(']')) break;
      SubLayer sub;
      sub.line = line_;
      ws();
      sub.column = column();
      auto a = asset_literal();
      if (!a) return a.error();
      sub.asset = *a;
      sub.resolved = resolve_asset(*a);
      ws();
      if (cur() == '(') {
        if (Status s = layer_offset(sub.offset, "/"); !s) return s;
      }
      layer.sublayers.push_back(std::move(sub));
    }
    return {};
  }

  Status skip_reorder() {
    // reorder nameChildren / properties / rootPrims = [ ... ]: order hints, read and dropped.
    auto what = identifier("'nameChildren' or 'properties'");
    if (!what) return what.error();
    if (Status s = expect('=', "after 'reorder " + *what + "'"); !s) return s;
    Value ignored;
    return value(ignored, "/", 1);
  }

  // ---- prims ---------------------------------------------------------------------------------------------

  Status prim_statement(PrimSpec& parent, int depth) {
    if (depth > kMaxDepth) return error("prims nested too deeply");
    ws();
    const int line = line_, col = column();
    Specifier spec;
    if (accept_word("def")) spec = Specifier::Def;
    else if (accept_word("over")) spec = Specifier::Over;
    else if (accept_word("class")) spec = Specifier::Class;
    else return error("expected 'def', 'over' or 'class', found " + found());
    std::string type;
    ws();
    if (ident_start(cur())) {
      auto t = identifier("a prim type name");
      if (!t) return t.error();
      type = std::move(*t);
    }
    auto name = string_literal();
    if (!name) return name.error();
    if (name->empty() || !ident_start((*name)[0]) ||
        !std::all_of(name->begin(), name->end(), [](char c) { return ident_char(c); }))
      return error_at(line, col, "'" + *name + "' is not a valid prim name (letters, digits and '_', not starting with a digit)");
    PrimSpec* prim = child_for(parent, *name, line, col);
    if (spec == Specifier::Def || prim->specifier == Specifier::Over) prim->specifier = spec;
    if (!type.empty()) prim->type_name = type;
    ws();
    if (cur() == '(') {
      ++i_;
      if (Status s = prim_metadata(*prim); !s) return s;
    }
    if (Status s = expect('{', "to open the body of prim '" + *name + "'"); !s) return s;
    return prim_body(*prim, depth);
  }

  // The child spec `name` of `parent` (a second spec of the same prim in one layer merges into the first).
  PrimSpec* child_for(PrimSpec& parent, const std::string& name, int line, int col) {
    auto it = parent.child_index.find(name);
    if (it != parent.child_index.end()) return parent.children[it->second].get();
    auto p = std::make_unique<PrimSpec>();
    p->name = name;
    p->path = parent.path == "/" ? "/" + name : parent.path + "/" + name;
    p->line = line;
    p->column = col;
    parent.child_index.emplace(name, parent.children.size());
    parent.children.push_back(std::move(p));
    return parent.children.back().get();
  }

  Status prim_body(PrimSpec& prim, int depth) {
    while (true) {
      ws();
      if (at_end()) return error("expected '}' to close prim '" + prim.name + "', found the end of the file");
      if (accept('}')) return {};
      if (accept(';')) continue;
      const std::string_view w = peek_word();
      if (w == "def" || w == "over" || w == "class") {
        if (Status s = prim_statement(prim, depth + 1); !s) return s;
      } else if (w == "variantSet") {
        i_ += w.size();
        if (Status s = variant_set(prim, depth); !s) return s;
      } else if (w == "reorder" && (peek_after_word("nameChildren") || peek_after_word("properties"))) {
        i_ += w.size();
        if (Status s = skip_reorder(); !s) return s;
      } else {
        if (Status s = property(prim); !s) return s;
      }
    }
  }

  // Whether the word after the current one is `w` (no consumption).
  bool peek_after_word(std::string_view w) {
    const std::size_t save = i_;
    const int line = line_;
    const std::size_t ls = line_start_;
    const std::string_view first = peek_word();
    i_ += first.size();
    const bool yes = peek_word() == w;
    i_ = save;
    line_ = line;
    line_start_ = ls;
    return yes;
  }

  Status variant_set(PrimSpec& prim, int depth) {
    auto name = string_literal();
    if (!name) return name.error();
    if (Status s = expect('=', "after variantSet \"" + *name + "\""); !s) return s;
    if (Status s = expect('{', "to open variantSet \"" + *name + "\""); !s) return s;
    VariantSetSpec* set = nullptr;
    for (auto& vs : prim.variant_sets)
      if (vs.name == *name) set = &vs;
    if (!set) {
      prim.variant_sets.push_back({*name, {}});
      set = &prim.variant_sets.back();
    }
    while (!accept('}')) {
      ws();
      const int line = line_, col = column();
      auto vname = string_literal();
      if (!vname) return vname.error();
      VariantSpec* variant = nullptr;
      for (auto& v : set->variants)
        if (v.name == *vname) variant = &v;
      if (!variant) {
        auto p = std::make_unique<PrimSpec>();
        p->name = prim.name;
        p->path = prim.path;
        p->specifier = Specifier::Over;
        p->line = line;
        p->column = col;
        set->variants.push_back({*vname, std::move(p)});
        variant = &set->variants.back();
      }
      ws();
      if (cur() == '(') {
        ++i_;
        if (Status s = prim_metadata(*variant->prim); !s) return s;
      }
      if (Status s = expect('{', "to open variant \"" + *vname + "\""); !s) return s;
      if (Status s = prim_body(*variant->prim, depth + 1); !s) return s;
    }
    return {};
  }

  // ---- prim metadata -------------------------------------------------------------------------------------

  enum class ListOpKind { Explicit, Prepend, Append, Delete, Reorder };

  ListOpKind list_op_prefix() {
    if (accept_word("prepend")) return ListOpKind::Prepend;
    if (accept_word("append") || accept_word("add")) return ListOpKind::Append;
    if (accept_word("delete")) return ListOpKind::Delete;
    if (accept_word("reorder")) return ListOpKind::Reorder;
    return ListOpKind::Explicit;
  }

  template <typename T>
  static void apply(ListOp<T>& op, ListOpKind kind, std::vector<T> items) {
    switch (kind) {
      case ListOpKind::Explicit:
        op.is_explicit = true;
        op.explicit_items = std::move(items);
        break;
      case ListOpKind::Prepend: op.prepended = std::move(items); break;
      case ListOpKind::Append: op.appended = std::move(items); break;
      case ListOpKind::Delete: op.deleted = std::move(items); break;
      case ListOpKind::Reorder: break;
    }
  }

  Status prim_metadata(PrimSpec& prim) {
    while (!accept(')')) {
      auto skipped = skip_separator_or_doc();
      if (!skipped) return skipped.error();
      if (*skipped) continue;
      const ListOpKind op = list_op_prefix();
      auto key = metadata_key("a metadata key");
      if (!key) return key.error();
      if (*key == "references" || *key == "payload") {
        std::vector<Reference> refs;
        if (Status s = references(refs, prim.path); !s) return s;
        apply(*key == "references" ? prim.references : prim.payloads, op, std::move(refs));
        continue;
      }
      Value v;
      if (Status s = value(v, prim.path, 1); !s) return s;
      if (*key == "inherits" || *key == "specializes") {
        if (v.kind != Value::Kind::Path && !v.is_none() && v.kind != Value::Kind::Empty)
          return error("'" + *key + "' takes prim paths (</Class>)");
        apply(*key == "inherits" ? prim.inherits : prim.specializes, op, std::move(v.text));
      } else if (*key == "variantSets" || *key == "apiSchemas") {
        if (v.kind != Value::Kind::String && !v.is_none() && v.kind != Value::Kind::Empty)
          return error("'" + *key + "' takes names (\"name\" or [\"a\", \"b\"])");
        apply(*key == "variantSets" ? prim.variant_set_names : prim.api_schemas, op, std::move(v.text));
      } else if (*key == "variants") {
        if (v.kind != Value::Kind::Dict) return error("'variants' takes a dictionary { string set = \"variant\" }");
        for (const auto& [set, sel] : *v.dict) {
          if (sel.kind == Value::Kind::String && sel.text.size() == 1) prim.variant_selections.emplace_back(set, sel.text[0]);
        }
      } else {
        prim.metadata.emplace_back(std::move(*key), std::move(v));
      }
    }
    return {};
  }

  // None, one reference or [ references ]: @asset@</prim> (offset = ...), </prim> (internal).
  Status references(std::vector<Reference>& out, const std::string& prim) {
    ws();
    if (accept_word("None")) return {};
    const bool list = accept('[');
    bool first = true;
    while (true) {
      if (list) {
        if (accept(']')) break;
        if (!first && !accept(',')) return error("expected ',' or ']' in a reference list, found " + found());
        if (accept(']')) break;
      }
      first = false;
      Reference r;
      ws();
      r.line = line_;
      r.column = column();
      if (cur() == '@') {
        auto a = asset_literal();
        if (!a) return a.error();
        r.asset = *a;
        r.resolved = resolve_asset(*a);
        if (cur() == '<') {
          auto p = path_literal("/");
          if (!p) return p.error();
          r.prim = *p;
        }
      } else if (cur() == '<') {
        auto p = path_literal("/");
        if (!p) return p.error();
        r.prim = *p;
      } else {
        return error("expected a reference (@file@</prim> or </prim>), found " + found());
      }
      ws();
      if (cur() == '(') {
        if (Status s = layer_offset(r.offset, prim); !s) return s;
      }
      out.push_back(std::move(r));
      if (!list) break;
    }
    return {};
  }

  // ---- properties ----------------------------------------------------------------------------------------

  PropertySpec& property_for(PrimSpec& prim, const std::string& name, int line, int col) {
    auto it = prim.property_index.find(name);
    if (it != prim.property_index.end()) return prim.properties[it->second];
    prim.property_index.emplace(name, prim.properties.size());
    prim.properties.emplace_back();
    PropertySpec& p = prim.properties.back();
    p.name = name;
    p.line = line;
    p.column = col;
    return p;
  }

  Status property(PrimSpec& prim) {
    ws();
    const int line = line_, col = column();
    const ListOpKind op = list_op_prefix();
    bool uniform = false;
    while (true) {
      if (accept_word("custom") || accept_word("varying") || accept_word("config")) continue;
      if (accept_word("uniform")) {
        uniform = true;
        continue;
      }
      break;
    }
    if (accept_word("rel")) return relationship(prim, op, line, col);
    auto type = identifier("a property declaration (type and name) or a prim");
    if (!type) return type.error();
    const TypeInfo info = type_info(*type);
    if (!info.known) return error_at(line, col, "unknown value type '" + *type + "'");
    bool array = false;
    if (accept('[')) {
      if (Status s = expect(']', "after '" + *type + "['"); !s) return s;
      array = true;
    }
    auto name = identifier("the name of the " + *type + " attribute");
    if (!name) return name.error();
    PropertySpec& p = property_for(prim, *name, line, col);
    p.type_name = *type;
    p.array = array;
    p.uniform = uniform;
    const std::string what = "'" + *type + (array ? "[] " : " ") + *name + "'";
    if (cur() == '.') {
      ++i_;
      auto suffix = identifier("'timeSamples', 'connect' or 'default' after '.'");
      if (!suffix) return suffix.error();
      if (*suffix == "timeSamples") {
        if (Status s = expect('=', "after " + what + ".timeSamples"); !s) return s;
        return time_samples(p, info, what, prim.path);
      }
      if (*suffix == "connect") {
        if (Status s = expect('=', "after " + what + ".connect"); !s) return s;
        Value v;
        if (Status s = value(v, prim.path, 1); !s) return s;
        if (v.kind != Value::Kind::Path && !v.is_none() && v.kind != Value::Kind::Empty)
          return error_at(line, col, "a connection of " + what + " must be a property path (<...>)");
        apply(p.connections, op, std::move(v.text));
        return optional_metadata(p, prim.path);
      }
      if (*suffix == "spline") return error_at(line, col, what + ".spline: animation splines are not supported (bake them to timeSamples)");
      if (*suffix != "default") return error("unknown property suffix '." + *suffix + "'");
    }
    if (accept('=')) {
      const int vline = line_;
      ws();
      const int vcol = column();
      Value v;
      if (Status s = value(v, prim.path, 1); !s) return s;
      if (Status s = check_type(v, info, array, what, vline, vcol); !s) return s;
      p.default_value = std::move(v);
      p.has_default = true;
    }
    return optional_metadata(p, prim.path);
  }

  Status relationship(PrimSpec& prim, ListOpKind op, int line, int col) {
    auto name = identifier("a relationship name");
    if (!name) return name.error();
    PropertySpec& p = property_for(prim, *name, line, col);
    p.relationship = true;
    if (cur() == '.') {
      ++i_;
      auto suffix = identifier("'default'");
      if (!suffix) return suffix.error();
      if (*suffix != "default") return error("unknown relationship suffix '." + *suffix + "'");
    }
    if (accept('[')) return error_at(line, col, "relational attributes (rel " + *name + "[<target>]) are not supported");
    if (accept('=')) {
      Value v;
      if (Status s = value(v, prim.path, 1); !s) return s;
      if (v.kind != Value::Kind::Path && !v.is_none() && v.kind != Value::Kind::Empty)
        return error_at(line, col, "the targets of relationship '" + *name + "' must be paths (<...>)");
      apply(p.targets, op, std::move(v.text));
    }
    return optional_metadata(p, prim.path);
  }

  Status optional_metadata(PropertySpec& p, const std::string& prim) {
    ws();
    if (cur() != '(') return {};
    ++i_;
    while (!accept(')')) {
      auto skipped = skip_separator_or_doc();
      if (!skipped) return skipped.error();
      if (*skipped) continue;
      list_op_prefix();
      auto key = metadata_key("a property metadata key");
      if (!key) return key.error();
      Value v;
      if (Status s = value(v, prim, 1); !s) return s;
      p.metadata.emplace_back(std::move(*key), std::move(v));
    }
    return {};
  }

  Status time_samples(PropertySpec& p, const TypeInfo& info, const std::string& what, const std::string& prim) {
    if (Status s = expect('{', "to open the time samples of " + what); !s) return s;
    p.time_samples.clear();
    while (true) {
      ws();
      if (at_end()) return error("expected '}' to close the time samples of " + what + ", found the end of the file");
      if (cur() == '}') {
        ++i_;
        break;
      }
      if (cur() == ',') {
        ++i_;
        continue;
      }
      double t = 0.0;
      if (!scan_number(t)) return error("expected a time code (a number), found " + found());
      if (!std::isfinite(t)) return error("time codes must be finite numbers");
      if (Status s = expect(':', "after the time code of a sample"); !s) return s;
      ws();
      const int vline = line_, vcol = column();
      Value v;
      if (cur() == '(') {  // the usual sample: one flat tuple
        const std::size_t save = i_, save_line_start = line_start_;
        int n = 0;
        if (flat_tuple(v.numbers, n)) {
          v.kind = Value::Kind::Number;
          v.tuple = n;
        } else {
          i_ = save;
          line_ = vline;
          line_start_ = save_line_start;
          v.numbers.clear();
        }
      }
      if (v.kind == Value::Kind::Empty)
        if (Status s = value(v, prim, 1); !s) return s;
      if (Status s = check_type(v, info, p.array, what, vline, vcol); !s) return s;
      p.time_samples.emplace_back(t, std::move(v));
    }
    // Sorted by time; of two samples at one time the later in the file wins.
    auto earlier = [](const auto& a, const auto& b) { return a.first < b.first; };
    if (!std::is_sorted(p.time_samples.begin(), p.time_samples.end(), earlier))
      std::stable_sort(p.time_samples.begin(), p.time_samples.end(), earlier);
    auto same = std::adjacent_find(p.time_samples.begin(), p.time_samples.end(),
                                   [](const auto& a, const auto& b) { return a.first == b.first; });
    if (same != p.time_samples.end()) {
      std::vector<std::pair<double, Value>> unique;
      for (auto& s : p.time_samples) {
        if (!unique.empty() && unique.back().first == s.first) unique.back() = std::move(s);
        else unique.push_back(std::move(s));
      }
      p.time_samples = std::move(unique);
    }
    return optional_metadata(p, prim);
  }

  std::string_view s_;
  std::vector<double> scratch_;
  std::string file_;
  std::string dir_;
  std::size_t i_ = 0;
  int line_ = 1;
  std::size_t line_start_ = 0;
};

}  // namespace

Expected<std::unique_ptr<Layer>> parse_usda(std::string_view text, const std::string& path) {
  return Parser(text, path).parse();
}

Expected<std::unique_ptr<Layer>> read_usda(const std::string& path) {
  // Only regular files: an asset path naming a device (/dev/zero, a pipe) must not hang the reader.
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) return Error::input(path, "cannot open the layer (no such file)");
  if (std::filesystem::file_size(path, ec) > (std::uintmax_t(1) << 31))
    return Error::input(path, "the layer is larger than 2 GiB");
  std::ifstream in(path, std::ios::binary);
  if (!in) return Error::input(path, "cannot open the layer (no permission?)");
  std::string text(static_cast<std::size_t>(std::filesystem::file_size(path, ec)), '\0');
  in.read(text.data(), static_cast<std::streamsize>(text.size()));
  text.resize(static_cast<std::size_t>(in.gcount()));
  if (text.rfind("PXR-USDC", 0) == 0 || text.rfind("PK\x03\x04", 0) == 0) {
    return Error::input(path, "a binary USD (crate) file or .usdz package, which cannot be read without OpenUSD; convert "
                              "it to text on a machine with OpenUSD: usdcat -o file.usda " +
                                  std::filesystem::path(path).filename().string());
  }
  return parse_usda(text, path);
}

}  // namespace temporal::usd
