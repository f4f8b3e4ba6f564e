// The documentation, run as a user runs it (issue 15): every ```sh block of README.md and
// docs/*.md is read from the Markdown file at test time and its lines run one by one with
// /bin/sh, from a private copy of the checkout (the source tree's files, `build` = this build),
// with a private XDG_RUNTIME_DIR (so the default socket is private too), no extra flags, daemons
// started exactly as the line starts them. doc_examples.cpp says what each line must do; a line
// that cannot run here is listed there as skipped, with the reason.
//
// Failures name the document line, what ran, what was expected and what happened, e.g.
//   README.md:76 `build/viewer/gpubridge-view &`: exited (exit status 3), and the daemon never listed
//   a subscribed gpubridge-view (`gpubridge --json status`)   [followed by its stdout and stderr]
#include <gtest/gtest.h>

#include <signal.h>
#include <sys/stat.h>

#include <algorithm>
#include <chrono>
#include <fstream>
#include <memory>
#include <regex>
#include <thread>

#include <nlohmann/json.hpp>

#include "../viewer/process.hpp"
#include "doc_commands.hpp"
#include "doc_examples.hpp"
#include "shell.hpp"

namespace gpubridge::readme {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

const fs::path kSource = GPUBRIDGE_SOURCE_DIR;
const fs::path kBuild = GPUBRIDGE_BUILD_DIR;

std::string tail(const std::string& s, std::size_t n = 3000) {
  return s.size() <= n ? s : "..." + s.substr(s.size() - n);
}

std::string outputs(const Outcome& o) {
  return "\n  --- stdout ---\n" + tail(o.out) + "\n  --- stderr ---\n" + tail(o.err);
}

bool contains(const std::string& text, const std::string& pattern) {
  return std::regex_search(text, std::regex(pattern, std::regex::ECMAScript));
}

bool is_png(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  char sig[8] = {};
  in.read(sig, 8);
  return in.gcount() == 8 && std::string(sig, 8) == "\x89PNG\r\n\x1a\n";
}

// A private checkout: the source tree's top-level entries as symlinks, `build` pointing at this
// build tree, and private runtime and home directories.
class Workspace {
 public:
  Workspace() {
    dir_ = std::make_unique<viewer::test::TempDir>();
    root_ = dir_->path();
    work_ = root_ / "checkout";
    logs_ = root_ / "logs";
    fs::create_directories(work_);
    fs::create_directories(logs_);
    fs::create_directories(root_ / "home");
    fs::create_directories(root_ / "run");
    ::chmod((root_ / "run").c_str(), 0700);  // as XDG_RUNTIME_DIR must be
    for (const auto& e : fs::directory_iterator(kSource)) {
      const std::string name = e.path().filename().string();
      if (name == ".git" || name.starts_with("build")) continue;
      fs::create_directory_symlink(e.path(), work_ / name);
    }
    fs::create_directory_symlink(kBuild, work_ / "build");
    env_.cwd = work_;
    const char* path = std::getenv("PATH");
    // The documents call installed programs by name (`gpubridged`, `gpubridge-view`): this build's.
    std::string p;
    for (const char* d : {"daemon", "tools", "viewer", "examples"}) p += (work_ / "build" / d).string() + ":";
    env_.set = {{"XDG_RUNTIME_DIR", (root_ / "run").string()},
                {"HOME", (root_ / "home").string()},
                {"PATH", p + (path ? path : "/usr/bin:/bin")}};
    env_.unset = {"GPUBRIDGE_TOKEN", "WAYLAND_DISPLAY", "DISPLAY"};
  }

  void set_display(const std::string& display) {
    std::erase(env_.unset, std::string("DISPLAY"));
    env_.set.emplace_back("DISPLAY", display);
  }
  const ShellEnv& env() const { return env_; }
  const fs::path& work() const { return work_; }
  const fs::path& logs() const { return logs_; }

 private:
  std::unique_ptr<viewer::test::TempDir> dir_;
  fs::path root_, work_, logs_;
  ShellEnv env_;
};

// One block's lines, run in order.
class BlockRunner {
 public:
  explicit BlockRunner(Workspace& ws) : ws_(ws) {}
  ~BlockRunner() { end_section(); }

  void run(const DocLine& line, const Step& step) {
    ++count_;
    const std::string cmd = step.run_instead.empty() ? line.command : step.run_instead;
    const std::string what = describe(line, step);
    switch (step.kind) {
      case Kind::Skip: return;
      case Kind::Run: {
        const Outcome o = run_shell(cmd, ws_.env(), ws_.logs(), name(), std::chrono::seconds(step.limit_s));
        check_outcome(what, step, o);
        for (const auto& f : step.files) {
          const fs::path p = ws_.work() / f;
          if (!fs::exists(p) || fs::file_size(p) == 0)
            ADD_FAILURE() << what << ": should leave the file " << f << ", which is missing or empty" << outputs(o);
          else if (p.extension() == ".png" && !is_png(p))
            ADD_FAILURE() << what << ": " << f << " is not a PNG file";
        }
        return;
      }
      case Kind::Daemon: {
        end_section();  // one daemon at a time, as a user runs them: the previous one stops first
        auto job = std::make_unique<ShellJob>("exec " + cmd, ws_.env(), ws_.logs(), name());
        const bool ready = wait_until([&] { return status(step.address).exit_code == 0; }, *job);
        if (!ready)
          ADD_FAILURE() << what << ": gpubridged never answered `gpubridge status` on "
                        << (step.address.empty() ? "the default socket" : step.address) << ": "
                        << (job->running() ? "still running" : job->wait(0ms)->status()) << outputs(job_outcome(*job));
        daemon_ = {&step, what, std::move(job), !ready};
        return;
      }
      case Kind::Alongside: {
        auto job = std::make_unique<ShellJob>("exec " + cmd, ws_.env(), ws_.logs(), name());
        const bool ready = !step.viewer || wait_until([&] { return viewer_subscribed(step.address); }, *job);
        if (!ready)
          ADD_FAILURE() << what << ": " << (job->running() ? "still running, but" : "exited (" + job->wait(0ms)->status() + "), and")
                        << " the daemon never listed a subscribed gpubridge-view (`gpubridge --json status`)"
                        << outputs(job_outcome(*job));
        alongside_.push_back({&step, what, std::move(job), !ready});
        return;
      }
    }
  }

  // Ends what runs alongside (newest first), then the daemon, checking how each ends.
  void end_section() {
    while (!alongside_.empty()) {
      finish(alongside_.back());
      alongside_.pop_back();
    }
    if (daemon_.job && !daemon_.failed) {
      const Outcome o = daemon_.job->stop(SIGTERM, 15s);
      if (o.timed_out || o.exit_code != 0)
        ADD_FAILURE() << daemon_.what << ": on SIGTERM it should shut down cleanly with exit status 0, but "
                      << o.status() << outputs(o);
      else
        check_output(daemon_.what, *daemon_.step, o);
    }
    daemon_ = {};
  }

 private:
  struct Running {
    const Step* step = nullptr;
    std::string what;
    std::unique_ptr<ShellJob> job;
    bool failed = false;  // already reported: its end is not checked again
  };

  std::string name() const { return "line" + std::to_string(count_); }

  static std::string describe(const DocLine& line, const Step& step) {
    std::string s = line.where() + " `" + line.command + (line.background ? " &" : "") + "`";
    if (!step.run_instead.empty()) s += " (run as `" + step.run_instead + "`: " + step.why + ")";
    return s;
  }

  static Outcome job_outcome(ShellJob& job) {
    if (auto o = job.wait(0ms)) return *o;
    Outcome o;
    o.out = job.out();
    o.err = job.err();
    return o;
  }

  void check_output(const std::string& what, const Step& step, const Outcome& o) {
    for (const auto& re : step.out)
      if (!contains(o.out, re)) ADD_FAILURE() << what << ": stdout should match /" << re << "/" << outputs(o);
    for (const auto& re : step.err)
      if (!contains(o.err, re)) ADD_FAILURE() << what << ": stderr should match /" << re << "/" << outputs(o);
  }

  void check_outcome(const std::string& what, const Step& step, const Outcome& o) {
    if (o.timed_out || o.signal || o.exit_code != step.exit) {
      ADD_FAILURE() << what << ": expected exit status " << step.exit << ", got " << o.status() << outputs(o);
      return;
    }
    check_output(what, step, o);
  }

  void finish(Running& r) {
    const Step& step = *r.step;
    if (r.failed) return;  // the destructor of its job ends it
    if (step.finishes) {
      auto o = r.job->wait(std::chrono::seconds(step.limit_s));
      if (!o) {
        const Outcome killed = r.job->stop(SIGKILL, 5s);
        ADD_FAILURE() << r.what << ": should have ended by itself within " << step.limit_s << " s" << outputs(killed);
        return;
      }
      check_outcome(r.what, step, *o);
      return;
    }
    if (step.viewer) {
      // The window shows the daemon's frames: its title names the address and the frame size.
      std::string tree;
      const bool shown = poll(10s, [&] {
        tree = run_shell("xwininfo -root -tree", ws_.env(), ws_.logs(), "xwininfo", 10s).out;
        for (const auto& re : step.window)
          if (!contains(tree, re)) return false;
        return true;
      });
      if (!shown)
        ADD_FAILURE() << r.what << ": the window should match /" << testing::PrintToString(step.window)
                      << "/ in `xwininfo -root -tree`, which lists:\n"
                      << tail(tree) << outputs(job_outcome(*r.job));
      if (!r.job->running())
        ADD_FAILURE() << r.what << ": closed before the end of its section: " << job_outcome(*r.job).status()
                      << outputs(job_outcome(*r.job));
    }
    // Closed as a user closes a window or a background job: SIGTERM.
    const Outcome o = r.job->stop(SIGTERM, 10s);
    if (o.timed_out) ADD_FAILURE() << r.what << ": did not end on SIGTERM" << outputs(o);
    else check_output(r.what, step, o);
  }

  template <class F>
  static bool poll(std::chrono::milliseconds limit, F ready) {
    const auto deadline = std::chrono::steady_clock::now() + limit;
    do {
      if (ready()) return true;
      std::this_thread::sleep_for(100ms);
    } while (std::chrono::steady_clock::now() < deadline);
    return false;
  }

  // Until ready() or the job ends (20 s at most: the machines running this are shared).
  template <class F>
  static bool wait_until(F ready, ShellJob& job) {
    const auto deadline = std::chrono::steady_clock::now() + 20s;
    do {
      if (ready()) return true;
      if (!job.running()) return false;
      std::this_thread::sleep_for(100ms);
    } while (std::chrono::steady_clock::now() < deadline);
    return false;
  }

  Outcome status(const std::string& address, bool json = false) const {
    std::string cmd = "build/tools/gpubridge";
    if (json) cmd += " --json";
    if (!address.empty()) cmd += " --connect '" + address + "'";
    return run_shell(cmd + " status", ws_.env(), ws_.logs(), "status", 10s);
  }

  bool viewer_subscribed(const std::string& address) const {
    const Outcome o = status(address, true);
    if (o.exit_code != 0) return false;
    const auto j = nlohmann::json::parse(o.out, nullptr, false);
    if (j.is_discarded() || !j.contains("clients") || !j["clients"].is_array()) return false;
    for (const auto& c : j["clients"])
      if (c.value("name", "") == "gpubridge-view" && c.value("subscribed", false)) return true;
    return false;
  }

  Workspace& ws_;
  int count_ = 0;
  Running daemon_;
  std::vector<Running> alongside_;
};

std::string documented(const DocLine& l) { return l.command + (l.background ? " &" : ""); }

// The block as the document has it now, or nullptr (with a failure saying so).
const DocBlock* find_block(const std::vector<DocBlock>& blocks, const Example& ex) {
  for (const auto& b : blocks)
    if (b.heading == ex.heading && b.ordinal == ex.ordinal) return &b;
  return nullptr;
}

class DocExample : public ::testing::TestWithParam<std::size_t> {};

TEST_P(DocExample, EveryLineRunsAsDocumented) {
  const Example& ex = documented_examples()[GetParam()];
  const auto blocks = shell_blocks(kSource, ex.file);
  const DocBlock* block = find_block(blocks, ex);
  ASSERT_TRUE(block) << ex.file << " has no shell block #" << ex.ordinal + 1 << " under \"" << ex.heading
                     << "\" any more; update its entry in tests/readme/doc_examples.cpp";
  // The document and the test must list the same lines, in the same order.
  const std::size_t n = std::max(block->lines.size(), ex.steps.size());
  for (std::size_t i = 0; i < n; ++i) {
    if (i >= ex.steps.size())
      FAIL() << block->lines[i].where() << ": `" << documented(block->lines[i])
             << "` is new: add a Step for it (what it must do, or why it is skipped) to \"" << ex.name
             << "\" in tests/readme/doc_examples.cpp";
    if (i >= block->lines.size())
      FAIL() << ex.file << " (block at line " << block->line << "): the test expects `" << ex.steps[i].line
             << "` as line " << i + 1 << " of the block, but the document ends before it; remove or update "
             << "its Step in tests/readme/doc_examples.cpp";
    if (documented(block->lines[i]) != ex.steps[i].line)
      FAIL() << block->lines[i].where() << ": the document says `" << documented(block->lines[i])
             << "` where tests/readme/doc_examples.cpp expects `" << ex.steps[i].line
             << "`; update the Step so that it says what the line must do now";
  }

  Workspace ws;
  std::unique_ptr<viewer::test::Xvfb> xvfb;
  bool display = true;
  for (const auto& s : ex.steps)
    if (s.viewer && !xvfb) {
      xvfb = std::make_unique<viewer::test::Xvfb>();
      if (xvfb->display().empty()) {
        if (std::getenv("CI")) FAIL() << "CI must run the viewer lines, but " << xvfb->reason();
        display = false;
      } else {
        ws.set_display(xvfb->display());
      }
    }
  BlockRunner runner(ws);
  std::vector<std::string> skipped;
  for (std::size_t i = 0; i < ex.steps.size(); ++i) {
    const Step& step = ex.steps[i];
    if (step.kind == Kind::Skip) {
      skipped.push_back(block->lines[i].where() + " `" + step.line + "`: " + step.why);
      continue;
    }
    if (step.viewer && !display) {
      skipped.push_back(block->lines[i].where() + " `" + step.line + "`: no X server (" + xvfb->reason() + ")");
      continue;
    }
    runner.run(block->lines[i], step);
  }
  runner.end_section();
  if (!skipped.empty()) {
    std::string list;
    for (const auto& s : skipped) list += "\n  " + s;
    RecordProperty("not_run", list);
    std::printf("Not run here:%s\n", list.c_str());
  }
}

INSTANTIATE_TEST_SUITE_P(Docs, DocExample, ::testing::Range(std::size_t{0}, documented_examples().size()),
                         [](const ::testing::TestParamInfo<std::size_t>& p) {
                           return documented_examples()[p.param].name;
                         });

// README.md and every docs/*.md, as they are in the source tree now.
std::vector<std::string> markdown_files() {
  std::vector<std::string> files{"README.md"};
  for (const auto& e : fs::directory_iterator(kSource / "docs"))
    if (e.path().extension() == ".md") files.push_back("docs/" + e.path().filename().string());
  std::sort(files.begin() + 1, files.end());
  return files;
}

// Every shell block of the documents has an entry (a new block cannot go untested), and every
// entry still has its block.
TEST(DocExamples, EveryShellBlockIsListed) {
  const auto files = markdown_files();
  for (const auto& file : files) {
    for (const auto& b : shell_blocks(kSource, file)) {
      bool listed = false;
      for (const auto& ex : documented_examples()) listed |= ex.file == file && ex.heading == b.heading && ex.ordinal == b.ordinal;
      if (!listed)
        ADD_FAILURE() << file << ":" << b.line << ": the shell block " << b.id()
                      << " has no entry in tests/readme/doc_examples.cpp; add one (each line run, or skipped "
                      << "with the reason)";
    }
  }
  for (const auto& ex : documented_examples())
    EXPECT_NE(std::find(files.begin(), files.end(), ex.file), files.end())
        << ex.name << ": " << ex.file << " is not README.md or a docs/*.md file";
}

}  // namespace
}  // namespace gpubridge::readme
