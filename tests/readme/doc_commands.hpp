#pragma once
// The shell examples of the documentation, read from the Markdown files themselves at test time:
// every fenced block marked ```sh (or bash / shell / console) in README.md and docs/*.md, split into
// command lines with their file and line number, so a failure can point at the line a user copies.
#include <filesystem>
#include <string>
#include <vector>

namespace gpubridge::readme {

struct DocLine {
  std::string file;        // relative to the source tree: "README.md", "docs/daemon.md"
  int line = 0;            // 1-based line number in that file
  std::string text;        // the line as written
  std::string command;     // without its trailing comment, spaces trimmed, without a final '&'
  std::string comment;     // the trailing "# ..." comment, if any (without the '#')
  bool background = false; // ends with '&': the shell runs it alongside the following lines
  std::string where() const { return file + ":" + std::to_string(line); }
};

struct DocBlock {
  std::string file;
  std::string heading;  // text of the nearest "#"-heading above the block ("Using it")
  int ordinal = 0;      // 0 for the first shell block under that heading, 1 for the second, ...
  int line = 0;         // line of the opening fence
  std::vector<DocLine> lines;
  std::string id() const { return file + " \"" + heading + "\"" + (ordinal ? " #" + std::to_string(ordinal + 1) : ""); }
};

// Splits one shell line into command and comment: a '#' outside quotes at the start or after a
// blank starts the comment (as in sh). Also sets `background`.
DocLine split_line(const std::string& file, int line, const std::string& text);

// Every shell block of one Markdown file; lines that are empty or only a comment are dropped, and
// lines ending in '\' are joined with the next.
std::vector<DocBlock> shell_blocks(const std::filesystem::path& source_dir, const std::string& relative_file);

}  // namespace gpubridge::readme
