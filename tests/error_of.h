// The emaki::Error that `f` throws; a test failure (and an empty Error) when it throws none.
#pragma once

#include <gtest/gtest.h>

#include <functional>

#include "core/error.h"

namespace emaki::test {

inline Error error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e;
  }
  ADD_FAILURE() << "no error";
  return Error("", "");
}

}  // namespace emaki::test
