// Text-trace writer: the canonical text form of a CommandStream. Reading it back gives the same
// commands (timestamps excepted), so binary → text → binary is byte-identical.
#include <cstdio>

#include "gpubridge/protocol/text_trace.hpp"
#include "gpubridge/protocol/trace.hpp"

namespace gpubridge::protocol {
namespace {

void append_hex_bytes(std::string& out, std::span<const std::uint8_t> bytes) {
  static constexpr char kDigits[] = "0123456789abcdef";
  out.reserve(out.size() + bytes.size() * 2);
  for (auto b : bytes) {
    out += kDigits[b >> 4];
    out += kDigits[b & 15];
  }
}

std::string hex32(std::uint32_t v) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%08X", v);
  return buf;
}

}  // namespace

std::string write_text_trace(const CommandStream& s) {
  std::string out = "# gpubridge text trace (spigpu v1); see docs/protocol.md, \"Traces\"\n";
  // `.meta` must stay on one line; the binary writer stores the same form.
  if (const std::string meta = trace_metadata_line(s.metadata_json); meta != "{}") out += ".meta " + meta + "\n";
  bool previous_was_frames = false;
  for (const auto& tc : s.commands) {
    const Command& c = tc.command;
    if (const auto* f = std::get_if<FramesCmd>(&c)) {
      // Two adjacent batches would merge when read back; .batch keeps the message boundary.
      if (previous_was_frames) out += ".batch\n";
      const FrameView v = f->view();
      for (std::size_t i = 0; i < v.size(); ++i) {
        const Frame fr = v[i];
        out += format_register_write(fr.index, fr.data);
        out += '\n';
      }
      previous_was_frames = true;
      continue;
    }
    previous_was_frames = false;
    if (const auto* u = std::get_if<UploadCmd>(&c)) {
      out += ".mem " + hex32(u->address) + " ";
      append_hex_bytes(out, u->data);
      out += '\n';
    } else if (const auto* fe = std::get_if<FenceCmd>(&c)) {
      out += ".fence " + std::to_string(fe->id) + "\n";
    } else if (const auto* r = std::get_if<ReadRegCmd>(&c)) {
      const RegisterDesc* d = find_register(r->index);
      char buf[8];
      std::snprintf(buf, sizeof buf, "0x%02X", r->index);
      out += ".read " + (d ? std::string(d->name) : std::string(buf)) + "\n";
    } else if (const auto* rb = std::get_if<ReadbackCmd>(&c)) {
      out += ".readback " + hex32(rb->address) + " " + std::to_string(rb->length) + "\n";
    }
  }
  return out;
}

}  // namespace gpubridge::protocol
