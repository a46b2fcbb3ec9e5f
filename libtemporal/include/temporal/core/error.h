// Errors returned by libtemporal. The library never prints or exits: every fallible function returns an
// Error (or an Expected<T>) carrying a category, the file it concerns and a message that says what is wrong
// and how to fix it. Tools turn them into `tool: file: message` and the exit codes of docs/cli.md.
#pragma once

#include <string>
#include <utility>
#include <variant>

namespace temporal {

// Categories map one-to-one onto the documented exit codes (docs/cli.md).
enum class ErrorKind {
  Usage = 1,      // bad command-line value or combination
  Input = 2,      // unreadable, corrupt, mismatched or incomplete input data
  Output = 4,     // an output could not be written
  Internal = 5,   // a broken invariant inside the library (a bug)
};

struct Error {
  ErrorKind kind = ErrorKind::Input;
  std::string file;     // the file concerned, empty when none
  std::string message;  // what is wrong and how to fix it

  static Error usage(std::string msg) { return {ErrorKind::Usage, {}, std::move(msg)}; }
  static Error input(std::string file, std::string msg) { return {ErrorKind::Input, std::move(file), std::move(msg)}; }
  static Error output(std::string file, std::string msg) { return {ErrorKind::Output, std::move(file), std::move(msg)}; }
  static Error internal(std::string msg) { return {ErrorKind::Internal, {}, std::move(msg)}; }
};

// Result of an operation that returns nothing but may fail.
class Status {
 public:
  Status() = default;
  Status(Error e) : error_(std::move(e)), ok_(false) {}  // NOLINT: implicit by design, `return Error{...};`
  static Status ok() { return {}; }
  explicit operator bool() const { return ok_; }
  bool is_ok() const { return ok_; }
  const Error& error() const { return error_; }

 private:
  Error error_;
  bool ok_ = true;
};

// A value or an Error (std::expected arrives with C++23; this is the subset the project needs).
template <typename T>
class Expected {
 public:
  Expected(T value) : v_(std::move(value)) {}  // NOLINT: implicit by design
  Expected(Error e) : v_(std::move(e)) {}       // NOLINT: implicit by design
  explicit operator bool() const { return v_.index() == 0; }
  bool has_value() const { return v_.index() == 0; }
  T& value() & { return std::get<0>(v_); }
  const T& value() const& { return std::get<0>(v_); }
  T&& value() && { return std::get<0>(std::move(v_)); }
  T& operator*() & { return value(); }
  const T& operator*() const& { return value(); }
  T* operator->() { return &value(); }
  const T* operator->() const { return &value(); }
  const Error& error() const { return std::get<1>(v_); }
  Status status() const { return has_value() ? Status() : Status(error()); }

 private:
  std::variant<T, Error> v_;
};

}  // namespace temporal
