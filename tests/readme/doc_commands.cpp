#include "doc_commands.hpp"

#include <fstream>
#include <map>
#include <stdexcept>

namespace gpubridge::readme {
namespace {

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t");
  if (b == std::string::npos) return "";
  const auto e = s.find_last_not_of(" \t");
  return s.substr(b, e - b + 1);
}

bool is_shell_fence(const std::string& t) {
  for (const char* lang : {"```sh", "```bash", "```shell", "```console"})
    if (t == lang) return true;
  return false;
}

}  // namespace

DocLine split_line(const std::string& file, int line, const std::string& text) {
  DocLine d;
  d.file = file;
  d.line = line;
  d.text = text;
  char quote = 0;
  std::size_t cut = text.size();
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (quote) {
      if (c == quote) quote = 0;
      else if (c == '\\' && quote == '"') ++i;
      continue;
    }
    if (c == '\'' || c == '"') quote = c;
    else if (c == '\\') ++i;
    else if (c == '#' && (i == 0 || text[i - 1] == ' ' || text[i - 1] == '\t')) {
      cut = i;
      break;
    }
  }
  d.command = trim(text.substr(0, cut));
  if (cut < text.size()) d.comment = trim(text.substr(cut + 1));
  // A single trailing '&' (not '&&') puts the command in the background.
  if (d.command.size() >= 1 && d.command.back() == '&' && (d.command.size() < 2 || d.command[d.command.size() - 2] != '&')) {
    d.background = true;
    d.command = trim(d.command.substr(0, d.command.size() - 1));
  }
  return d;
}

std::vector<DocBlock> shell_blocks(const std::filesystem::path& source_dir, const std::string& relative_file) {
  std::ifstream in(source_dir / relative_file);
  if (!in) throw std::runtime_error("cannot read " + (source_dir / relative_file).string());
  std::vector<DocBlock> blocks;
  std::map<std::string, int> per_heading;
  std::string heading, text;
  bool inside = false, other_fence = false;
  int number = 0;
  std::string pending;  // a line continued with '\'
  int pending_line = 0;
  while (std::getline(in, text)) {
    ++number;
    const std::string t = trim(text);
    if (!inside && !other_fence && t.starts_with("#")) {
      const auto b = t.find_first_not_of('#');
      if (b != std::string::npos && t[b] == ' ') heading = trim(t.substr(b));
      continue;
    }
    if (t.starts_with("```")) {
      if (inside) {
        inside = false;
      } else if (other_fence) {
        other_fence = false;
      } else if (is_shell_fence(t)) {
        inside = true;
        blocks.push_back({relative_file, heading, per_heading[heading]++, number, {}});
      } else {
        other_fence = true;
      }
      continue;
    }
    if (!inside) continue;
    if (!text.empty() && text.back() == '\\') {
      if (pending.empty()) pending_line = number;
      pending += text.substr(0, text.size() - 1);
      continue;
    }
    const int at = pending.empty() ? number : pending_line;
    DocLine d = split_line(relative_file, at, pending + text);
    pending.clear();
    if (!d.command.empty()) blocks.back().lines.push_back(std::move(d));
  }
  return blocks;
}

}  // namespace gpubridge::readme
