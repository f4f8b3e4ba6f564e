#pragma once
// What every documented shell line must do when a user runs it (tests/readme/doc_examples.cpp):
// one Example per ```sh block of README.md and docs/*.md, one Step per command line, in order.
// readme_test.cpp reads the blocks from the Markdown files at test time and fails when a line
// and its step no longer agree, so the documents cannot drift from the product unnoticed.
#include <string>
#include <vector>

namespace gpubridge::readme {

enum class Kind {
  Run,        // runs to completion: exit status, output and files are checked
  Daemon,     // gpubridged: serves until stopped; ready when `gpubridge status` answers on its
              // address; stopped with SIGTERM (exit status 0) when the next daemon starts (one at a
              // time, as a user runs them) or at the end of the block, after the lines that use it
  Alongside,  // runs beside the following lines (`line &`, or a window a user keeps open): ends by
              // itself (`finishes`) or is closed at the end of its daemon's section
              // (Daemon and Alongside lines are one command each: the shell execs it, so that
              // signals reach the program)
  Skip,       // cannot run here; `why` says why and where it is covered instead
};

struct Step {
  std::string line;         // the documented command without its comment, " &" kept when backgrounded
  Kind kind = Kind::Run;
  std::string why;          // Skip: why; with run_instead: why the line runs in another form
  std::string run_instead;  // runs in place of the line: its documented no-hardware form, or the
                            // same command with a path/port that parallel test runs cannot share
  int exit = 0;             // expected exit status (Run, and Alongside with finishes)
  std::vector<std::string> out;    // regular expressions (ECMAScript) stdout must contain
  std::vector<std::string> err;    // ... stderr must contain
  std::vector<std::string> files;  // files it must leave in the working directory (.png: a PNG)
  std::string address;      // Daemon: where it serves ("" = the default socket); Alongside viewer:
                            // the daemon to watch for its subscription
  bool viewer = false;      // Alongside: a gpubridge-view window; ready once the daemon lists it
                            // as a subscribed client
  std::vector<std::string> window;  // viewer: regexes the X window tree (xwininfo) must contain
                                    // before it is closed (its title names address and frame size)
  bool finishes = false;    // Alongside: ends by itself before the end of its section
  int limit_s = 60;         // time limit of a Run line (or of a finishing Alongside line)

  // Builders, so that an entry reads as what the line must do:
  //   run("gpubridge status").prints("backend: +sim")
  Step&& prints(std::string re) && { out.push_back(std::move(re)); return std::move(*this); }
  Step&& warns(std::string re) && { err.push_back(std::move(re)); return std::move(*this); }
  Step&& leaves(std::string file) && { files.push_back(std::move(file)); return std::move(*this); }
  Step&& exits(int status) && { exit = status; return std::move(*this); }
  Step&& within(int seconds) && { limit_s = seconds; return std::move(*this); }
  Step&& instead(std::string command, std::string reason) && {
    run_instead = std::move(command);
    why = std::move(reason);
    return std::move(*this);
  }
};

// A line that runs to completion.
inline Step run(std::string line) {
  Step s;
  s.line = std::move(line);
  return s;
}
// A line that cannot run in a test, and why (say where it is covered instead).
inline Step skip(std::string line, std::string why) {
  Step s;
  s.line = std::move(line);
  s.kind = Kind::Skip;
  s.why = std::move(why);
  return s;
}
// gpubridged serving on `address` ("" = the default socket) until the next daemon or the block's end.
inline Step daemon(std::string line, std::string address = "") {
  Step s;
  s.line = std::move(line);
  s.kind = Kind::Daemon;
  s.address = std::move(address);
  return s;
}
// A gpubridge-view window beside the following lines: it must subscribe, and the X window tree
// must match `window` (its title: address, device, frame size) before it is closed.
inline Step viewer(std::string line, std::vector<std::string> window) {
  Step s;
  s.line = std::move(line);
  s.kind = Kind::Alongside;
  s.viewer = true;
  s.window = std::move(window);
  return s;
}
// `line &` that ends by itself (checked like a Run line at the end of its section).
inline Step alongside(std::string line) {
  Step s;
  s.line = std::move(line);
  s.kind = Kind::Alongside;
  s.finishes = true;
  return s;
}

struct Example {
  std::string file;     // "README.md", "docs/daemon.md"
  std::string heading;  // the heading the block is under
  int ordinal = 0;      // which shell block under that heading (0 = the first)
  std::string name;     // the test's name
  std::vector<Step> steps;
};

// Every shell block of README.md and docs/*.md, and what its lines must do.
const std::vector<Example>& documented_examples();

}  // namespace gpubridge::readme
