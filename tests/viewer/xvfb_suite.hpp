#pragma once
// Base fixture of the viewer suites that need an X server: one private Xvfb per suite. Without
// one a test is skipped, except under CI, where the viewer tests must run.
#include <gtest/gtest.h>

#include <cstdlib>
#include <memory>

#include "process.hpp"

namespace gpubridge::viewer::test {

class XvfbSuite : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { xvfb_ = std::make_unique<Xvfb>(); }
  static void TearDownTestSuite() { xvfb_.reset(); }
  // Derived SetUp()s call this first and return when it skipped or failed the test.
  void SetUp() override {
    if (!xvfb_->display().empty()) return;
    const char* suite = ::testing::UnitTest::GetInstance()->current_test_suite()->name();
    if (std::getenv("CI")) FAIL() << "CI must run the viewer tests (" << suite << ") but " << xvfb_->reason();
    GTEST_SKIP() << suite << " skipped: " << xvfb_->reason();
  }
  bool no_display() const { return IsSkipped() || HasFatalFailure(); }

  static inline std::unique_ptr<Xvfb> xvfb_;
};

}  // namespace gpubridge::viewer::test
