/// @file result.hpp
/// @brief Errors as values: the library never throws across its API, never prints, never exits.
#pragma once

#include <string>
#include <string_view>
#include <utility>
#include <variant>

namespace sgbake {

/// @brief What kind of failure an Error reports; the CLI maps these to exit codes.
enum class ErrorCode {
  kBadInput,  ///< the caller's data or file is wrong (missing, malformed, unsupported): exit 2
  kInternal,  ///< a bug or resource failure inside sgbake: exit 1
  kCancelled,  ///< the caller stopped the work (a progress callback returned false)
};

/// @brief A failure with a one-line, human-readable message that names the file (when there is
/// one) and what is wrong with it, e.g. `mesh.obj:12: face refers to vertex 99 of 3`.
struct Error {
  ErrorCode code = ErrorCode::kBadInput;
  std::string message;

  static Error badInput(std::string msg) { return {ErrorCode::kBadInput, std::move(msg)}; }
  static Error internal(std::string msg) { return {ErrorCode::kInternal, std::move(msg)}; }
};

/// @brief Either a value or an Error (a minimal std::expected for C++20).
template <class T>
class [[nodiscard]] Result {
 public:
  Result(T value) : data_(std::move(value)) {}  // NOLINT(google-explicit-constructor)
  Result(Error error) : data_(std::move(error)) {}  // NOLINT(google-explicit-constructor)

  bool ok() const { return std::holds_alternative<T>(data_); }
  explicit operator bool() const { return ok(); }

  /// @note Precondition: ok().
  T& value() & { return std::get<T>(data_); }
  const T& value() const& { return std::get<T>(data_); }
  T&& value() && { return std::get<T>(std::move(data_)); }
  T* operator->() { return &value(); }
  const T* operator->() const { return &value(); }
  T& operator*() & { return value(); }
  const T& operator*() const& { return value(); }

  /// @note Precondition: !ok().
  const Error& error() const { return std::get<Error>(data_); }

 private:
  std::variant<T, Error> data_;
};

/// @brief Result of an operation that produces no value.
struct Ok {};
using Status = Result<Ok>;

/// @brief @p text made safe inside a one-line message (a file name, an image name from the
/// caller): control characters, newlines included, become '?'.
inline std::string printableText(std::string_view text) {
  std::string out(text);
  for (char& c : out) {
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = '?';
  }
  return out;
}

}  // namespace sgbake
