// `gpubridge flash` run as a user runs it, with stand-in programmers on PATH: small scripts named
// openFPGALoader and iceprog that record their arguments and exit as told. Nothing about a real
// flash can be tested without a board; this checks the command line the CLI builds, what it
// refuses before touching a board, and what it says when the programmer fails.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "../viewer/process.hpp"

namespace {

using gpubridge::viewer::test::ProcessResult;
using gpubridge::viewer::test::run_process;
using gpubridge::viewer::test::TempDir;

class FlashCli : public ::testing::Test {
 protected:
  void SetUp() override {
    bin_ = tmp_.path() / "bin";
    std::filesystem::create_directories(bin_);
    std::filesystem::create_directories(tmp_.path() / "bitstreams");
    write_programmer("openFPGALoader");
    write_programmer("iceprog");
    // What icepack writes: a comment block, then the sync word.
    std::string bin("\xFF\x00Lattice\x00\x00\xFF\x7E\xAA\x99\x7E", 16);
    bin.resize(104090, '\0');
    write(tmp_.path() / "bitstreams" / "icebreaker.bin", bin);
    // ecppack's for an LFE5U-85F: comment, preamble, dummies, LSC_RESET_CRC, VERIFY_ID 0x41113043.
    std::string bit("\xFF\x00Part\x00\x00\xFF\xFF\xFF\xBD\xB3\xFF\xFF\xFF\xFF\x3B\x00\x00\x00\xE2\x00\x00\x00\x41\x11\x30\x43", 29);
    bit.resize(4096, '\0');
    write(tmp_.path() / "bitstreams" / "ulx3s.bit", bit);
  }

  // A programmer that writes its arguments, one per line, to <name>.args and exits with $FAKE_EXIT.
  void write_programmer(const std::string& name) {
    const auto path = bin_ / name;
    write(path, "#!/bin/sh\nprintf '%s\\n' \"$@\" > \"$FAKE_LOG_DIR/" + name + ".args\"\necho \"" + name +
                    " pretending\"\nexit ${FAKE_EXIT:-0}\n");
    ::chmod(path.c_str(), 0755);
  }

  static void write(const std::filesystem::path& path, const std::string& text) {
    std::ofstream(path, std::ios::binary) << text;
  }

  ProcessResult flash(std::vector<std::string> args, std::vector<std::string> env = {}) {
    std::vector<std::string> argv{GPUBRIDGE_CLI};
    argv.insert(argv.end(), args.begin(), args.end());
    env.push_back("PATH=" + bin_.string());
    env.push_back("FAKE_LOG_DIR=" + tmp_.path().string());
    env.push_back("GPUBRIDGE_BITSTREAM_DIR=" + (tmp_.path() / "bitstreams").string());
    return run_process(argv, env);
  }

  std::string args_of(const std::string& programmer) const {
    std::ifstream in(tmp_.path() / (programmer + ".args"));
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
  }
  bool ran(const std::string& programmer) const { return std::filesystem::exists(tmp_.path() / (programmer + ".args")); }
  std::string bitstream() const { return (tmp_.path() / "bitstreams" / "icebreaker.bin").string(); }

  TempDir tmp_;
  std::filesystem::path bin_;
};

TEST_F(FlashCli, FlashesTheBoardsBuiltBitstreamWithOpenFpgaLoader) {
  const auto r = flash({"flash", "--board", "icebreaker"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(args_of("openFPGALoader"), "-b\nice40_generic\n" + bitstream() + "\n");
  EXPECT_FALSE(ran("iceprog"));
  EXPECT_NE(r.out.find("next: gpubridge bringup --board icebreaker"), std::string::npos) << r.out;
  // The programmer's own output goes to stderr, with the command line it was given.
  EXPECT_NE(r.err.find("openFPGALoader pretending"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("openFPGALoader -b ice40_generic"), std::string::npos) << r.err;
}

TEST_F(FlashCli, SramGoesThroughIceprogAndJsonReportsIt) {
  const auto r = flash({"--json", "flash", "--board", "icebreaker", "--to", "sram"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(args_of("iceprog"), "-d\ni:0x0403:0x6010\n-I\nA\n-S\n" + bitstream() + "\n");
  const auto j = nlohmann::json::parse(r.out);  // stdout is the report alone
  EXPECT_EQ(j["result"], "ok");
  EXPECT_EQ(j["tool"], "iceprog");
  EXPECT_EQ(j["target"], "sram");
  EXPECT_EQ(j["exit_code"], 0);
  EXPECT_EQ(j["bitstream_bytes"], 104090);
}

TEST_F(FlashCli, AFailingProgrammerIsAFailureWithTheUdevAdvice) {
  const auto r = flash({"flash", "--board", "icebreaker"}, {"FAKE_EXIT=3"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("openFPGALoader failed (exit 3)"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("configs/udev/70-gpubridge.rules"), std::string::npos) << r.err;
}

TEST_F(FlashCli, AMissingProgrammerSaysWhichPackage) {
  std::filesystem::remove(bin_ / "openFPGALoader");
  std::filesystem::remove(bin_ / "iceprog");
  const auto r = flash({"flash", "--board", "icebreaker"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("openFPGALoader is not installed"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("apt-get install openfpgaloader"), std::string::npos) << r.err;
  // With only iceprog installed, the flash goes through it.
  write_programmer("iceprog");
  const auto r2 = flash({"flash", "--board", "icebreaker"});
  ASSERT_EQ(r2.exit_code, 0) << r2.err;
  EXPECT_EQ(args_of("iceprog"), "-d\ni:0x0403:0x6010\n-I\nA\n" + bitstream() + "\n");
}

TEST_F(FlashCli, NoBitstreamSaysWhereItLookedAndHowToBuildOne) {
  std::filesystem::remove(bitstream());
  const auto r = flash({"flash", "--board", "icebreaker"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("no bitstream for icebreaker at " + bitstream()), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("gpubridge flash --board icebreaker FILE"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("GPUBRIDGE_BITSTREAM_DIR"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("scripts/gateware.sh --board icebreaker"), std::string::npos) << r.err;
  EXPECT_FALSE(ran("openFPGALoader"));
}

// --board takes a profile file as probe and bringup do: a copy of the shipped one, renamed.
TEST_F(FlashCli, ABoardProfileFileWorksLikeItsName) {
  const auto file = tmp_.path() / "my-icebreaker.json";
  std::filesystem::copy_file(std::filesystem::path(GPUBRIDGE_TEST_CONFIG_DIR) / "boards" / "icebreaker.json", file);
  auto r = flash({"flash", "--board", file.string(), bitstream(), "--dry-run"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out, "openFPGALoader -b ice40_generic " + bitstream() + "\n");
  const auto uart = tmp_.path() / "my-dmc1.json";
  std::filesystem::copy_file(std::filesystem::path(GPUBRIDGE_TEST_CONFIG_DIR) / "boards" / "icebreaker-dmc1.json", uart);
  r = flash({"flash", "--board", uart.string(), bitstream(), "--to", "sram", "--dry-run"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out, "iceprog -d i:0x0403:0x6010 -I A -S " + bitstream() + "\n");
  r = flash({"flash", "--board", (tmp_.path() / "none.json").string()});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("none.json: cannot read"), std::string::npos) << r.err;
}

TEST_F(FlashCli, AFileThatIsNoBitstreamNeverReachesTheBoard) {
  const auto asc = tmp_.path() / "design.asc";
  write(asc, ".comment from nextpnr\n.device 5k\n");
  auto r = flash({"flash", "--board", "icebreaker", asc.string()});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("not an iCE40 bitstream"), std::string::npos) << r.err;
  EXPECT_FALSE(ran("openFPGALoader"));
  // An iCE40 bitstream offered to the ECP5 board.
  r = flash({"flash", "--board", "ulx3s", bitstream()});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("not an ECP5 bitstream"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("board ulx3s: ECP5 LFE5U-85F"), std::string::npos) << r.err;
  r = flash({"flash", "--board", "icebreaker", (tmp_.path() / "missing.bin").string()});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("missing.bin: no such file"), std::string::npos) << r.err;
  EXPECT_FALSE(ran("openFPGALoader"));
}

TEST_F(FlashCli, BoardsWithoutARecipeOrWithForeignBitstreamsSayWhatToDo) {
  auto r = flash({"flash", "--board", "icepi-zero"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("has no \"flash\" section"), std::string::npos) << r.err;
  r = flash({"flash", "--board", "icebreaker-dmc1"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("tinygpus"), std::string::npos) << r.err;
  // Given the DMC-1 SOC's bitstream, the same board flashes like any iCE40 board.
  r = flash({"flash", "--board", "icebreaker-dmc1", bitstream()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(args_of("openFPGALoader"), "-b\nice40_generic\n" + bitstream() + "\n");
  r = flash({"flash", "--board", "nosuch"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("no board profile named \"nosuch\""), std::string::npos) << r.err;
  r = flash({"flash", "--board", "ulx3s", "--tool", "iceprog"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("iceprog cannot write its flash (can: openfpgaloader)"), std::string::npos) << r.err;
  EXPECT_FALSE(ran("iceprog"));
}

TEST_F(FlashCli, DryRunPrintsTheCommandAndRunsNothing) {
  const auto r = flash({"flash", "--board", "icebreaker", "--dry-run"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out, "openFPGALoader -b ice40_generic " + bitstream() + "\n");
  const auto ulx = flash({"flash", "--board", "ulx3s", "--to", "sram", "--dry-run"});
  ASSERT_EQ(ulx.exit_code, 0) << ulx.err;
  EXPECT_EQ(ulx.out, "openFPGALoader -b ulx3s -m " + (tmp_.path() / "bitstreams" / "ulx3s.bit").string() + "\n");
  EXPECT_FALSE(ran("openFPGALoader"));
}

TEST_F(FlashCli, HelpAndBoardsSayWhichBitstreamGoesWithWhichBoard) {
  auto r = flash({"flash", "--help"});
  ASSERT_EQ(r.exit_code, 0);
  EXPECT_NE(r.out.find("--to"), std::string::npos);
  EXPECT_NE(r.out.find("GPUBRIDGE_BITSTREAM_DIR"), std::string::npos);
  r = flash({"boards"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("icebreaker       icebreaker.bin   openfpgaloader (flash), iceprog (flash, sram)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("ulx3s            ulx3s.bit        openfpgaloader (flash, sram)"), std::string::npos) << r.out;
  r = flash({"--json", "boards"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  bool seen = false;
  for (const auto& b : nlohmann::json::parse(r.out))
    if (b["name"] == "icebreaker") {
      seen = true;
      EXPECT_EQ(b["flash"]["bitstream"], "icebreaker.bin");
      EXPECT_EQ(b["flash"]["programmers"]["iceprog"], (nlohmann::json{"flash", "sram"}));
    }
  EXPECT_TRUE(seen);
}

}  // namespace
