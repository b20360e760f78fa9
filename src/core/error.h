// emaki::Error — the one error type for what a user can get wrong (a file, an option, a config
// key). It carries the subject so that apps/ can print one line naming it. Invariants are
// checks (check.h), not Errors.
#pragma once

#include <stdexcept>
#include <string>

namespace emaki {

class Error : public std::runtime_error {
 public:
  // A neutral name for a setting ("clip", "start", "aa", "frames", "gltf_node"). Code below the
  // front ends does not know whether the setting came from `--clip`, `source.clip` or a Python
  // argument, so it names the field and each front end re-spells it once (respelled()).
  struct Field {
    std::string name;
  };

  // subject: the file path, option name or config key the message is about (may be empty).
  Error(std::string subject, const std::string& message)
      : std::runtime_error(subject.empty() ? message : subject + ": " + message),
        subject_(std::move(subject)),
        message_(message) {}
  // Until a front end re-spells it, the field's neutral name is the subject: a true name, if
  // not the one the user typed.
  Error(Field field, const std::string& message) : Error(field.name, message) {
    field_ = std::move(field.name);
  }

  const std::string& subject() const { return subject_; }
  // The neutral field name, or empty when the subject is already a front end's own name.
  const std::string& field() const { return field_; }
  // The text without the subject.
  const std::string& message() const { return message_; }
  // The same error named `subject` (a front end's spelling of field()); it has no field left
  // to re-spell, so an outer front end cannot rename it a second time.
  Error respelled(std::string subject) const { return Error(std::move(subject), message_); }

 private:
  std::string subject_;
  std::string field_;
  std::string message_;
};

}  // namespace emaki
