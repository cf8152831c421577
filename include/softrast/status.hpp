// softrast/status.hpp: recoverable errors (files, user input) as values.
// Contract violations inside the pipeline are checks, not Status; only the CLI prints and exits.
#pragma once

#include <optional>
#include <string>
#include <utility>

namespace softrast {

// The outcome of an operation that can fail for reasons outside the program's control.
// An ok Status carries no message; an error carries one line meant for a human ("file: what").
class [[nodiscard]] Status {
 public:
  Status() = default;
  static Status error(std::string message) { return Status(std::move(message)); }

  bool ok() const { return !message_.has_value(); }
  explicit operator bool() const { return ok(); }
  // The error message; empty for an ok status.
  const std::string& message() const {
    static const std::string kEmpty;
    return message_ ? *message_ : kEmpty;
  }

 private:
  explicit Status(std::string message) : message_(std::move(message)) {}
  std::optional<std::string> message_;
};

// Either a value or an error Status (a small stand-in for C++23 std::expected).
template <class T>
class [[nodiscard]] Result {
 public:
  Result(T value) : value_(std::move(value)) {}  // NOLINT: implicit by design
  // Precondition: !error.ok() (an ok Status carries no value; it becomes an internal error).
  Result(Status error)  // NOLINT: implicit by design
      : status_(error.ok() ? Status::error("internal error: result without a value")
                           : std::move(error)) {}

  bool ok() const { return value_.has_value(); }
  explicit operator bool() const { return ok(); }
  const Status& status() const { return status_; }
  // Precondition: ok().
  T& value() & { return *value_; }
  const T& value() const& { return *value_; }
  T&& value() && { return std::move(*value_); }
  T* operator->() { return &*value_; }
  const T* operator->() const { return &*value_; }
  T& operator*() & { return *value_; }
  const T& operator*() const& { return *value_; }

 private:
  std::optional<T> value_;
  Status status_;
};

}  // namespace softrast
