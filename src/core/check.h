// Invariant checks that print the values that failed (after pbrt's CHECK_*). A failed check is
// a bug in emaki, never a user error: it aborts.
#pragma once

#include <cstdio>
#include <cstdlib>
#include <sstream>

namespace emaki::detail {
template <typename A, typename B>
[[noreturn]] void check_failed(const char* file, int line, const char* expr, const A& a,
                               const B& b) {
  std::ostringstream os;
  os << file << ":" << line << ": check failed: " << expr << " with " << a << " vs " << b;
  std::fprintf(stderr, "%s\n", os.str().c_str());
  std::abort();
}
}  // namespace emaki::detail

#define EMAKI_CHECK_OP(a, b, op)                                                      \
  do {                                                                                \
    const auto& va_ = (a);                                                            \
    const auto& vb_ = (b);                                                            \
    if (!(va_ op vb_))                                                                \
      ::emaki::detail::check_failed(__FILE__, __LINE__, #a " " #op " " #b, va_, vb_); \
  } while (0)
#define CHECK(x) EMAKI_CHECK_OP(bool(x), true, ==)
#define CHECK_EQ(a, b) EMAKI_CHECK_OP(a, b, ==)
#define CHECK_NE(a, b) EMAKI_CHECK_OP(a, b, !=)
#define CHECK_LT(a, b) EMAKI_CHECK_OP(a, b, <)
#define CHECK_LE(a, b) EMAKI_CHECK_OP(a, b, <=)
#define CHECK_GT(a, b) EMAKI_CHECK_OP(a, b, >)
#define CHECK_GE(a, b) EMAKI_CHECK_OP(a, b, >=)
