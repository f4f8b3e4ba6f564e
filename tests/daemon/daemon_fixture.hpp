#pragma once
// A daemon test with its own directory (named after the test, for its socket, keys and files) and
// a Daemon process that is stopped before the directory is removed.
#include <gtest/gtest.h>

#include "daemon_process.hpp"

namespace gpubridge::test {

class DaemonDirTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = make_temp_dir(::testing::UnitTest::GetInstance()->current_test_info()->name());
    socket_ = (dir_ / "d.sock").string();
  }
  void TearDown() override {
    daemon_.stop();
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  fs::path dir_;
  std::string socket_;
  Daemon daemon_;
};

}  // namespace gpubridge::test
