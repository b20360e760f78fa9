// emaki::Error — the one error type for what a user can get wrong (a file, an option, a config
// key). It carries the subject so that apps/ can print one line naming it. Invariants are
// checks (check.h), not Errors.
#pragma once

#include <stdexcept>
#include <string>

namespace emaki {

class Error : public std::runtime_error {
 public:
  // subject: the file path, option name or config key the message is about (may be empty).
  Error(std::string subject, const std::string& message)
      : std::runtime_error(subject.empty() ? message : subject + ": " + message),
        subject_(std::move(subject)) {}
  const std::string& subject() const { return subject_; }

 private:
  std::string subject_;
};

}  // namespace emaki
