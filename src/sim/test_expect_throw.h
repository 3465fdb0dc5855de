// Test helper: a call that must fail with a message naming what was wrong.
#ifndef CLOTHWIND_SIM_TEST_EXPECT_THROW_H_
#define CLOTHWIND_SIM_TEST_EXPECT_THROW_H_

#include <exception>
#include <functional>
#include <string>

#include <gtest/gtest.h>

namespace clothwind::sim {

// Expects fn() to throw a std::exception whose what() contains `needle` (why: the project's bad
// input errors must name the file, line or field, so the text is what a test checks, not only
// the exception's type). Records a failure, not an abort, so the remaining cases still run.
inline void ExpectThrowContaining(const std::function<void()>& fn, const std::string& needle) {
  try {
    fn();
    ADD_FAILURE() << "expected an exception containing '" << needle << "'";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
  }
}

}  // namespace clothwind::sim

#endif  // CLOTHWIND_SIM_TEST_EXPECT_THROW_H_
