// Fuzzes scene files: parse_scene on the input as JSON text, then build_commands when it parses.
// Inline textures ("png_base64", "rgba") are decoded; "png" file references are skipped (the
// harness must not read arbitrary paths such as FIFOs). Properties: a refused scene gives an
// error that names the file; an accepted one builds into commands the socket protocol carries
// unchanged (command_problem is empty) whose register writes the register table accepts as they
// are (check_write reports no error and clears no bit), uploads that stay inside video memory, and
// a final FB_DISPLAY of the colour buffer.
#include <string_view>
#include <variant>

#include <nlohmann/json.hpp>

#include "fuzz_check.hpp"
#include "gpubridge/protocol/registers.hpp"
#include "gpubridge/scene/scene.hpp"

namespace {

using namespace gpubridge;

bool references_png_file(std::string_view text) {
  const auto doc = nlohmann::json::parse(text, nullptr, false);
  if (doc.is_discarded() || !doc.is_object() || !doc.contains("textures") || !doc["textures"].is_array()) return false;
  for (const auto& t : doc["textures"])
    if (t.is_object() && t.contains("png")) return true;
  return false;
}

void check_frames(const protocol::FramesCmd& f) {
  FUZZ_CHECK(f.size() > 0);
  FUZZ_CHECK(f.bytes.size() == f.size() * protocol::kFrameBytes);
  const auto view = f.view();
  FUZZ_CHECK(protocol::first_read_frame(view) == view.size());
  for (std::size_t i = 0; i < view.size(); ++i) {
    const protocol::Frame frame = view[i];
    const auto check = protocol::check_write(frame.index, frame.data);
    if (check.errors != 0 || check.data != frame.data)
      std::fprintf(stderr, "frame %zu: register 0x%02x data 0x%016llx: %s (errors 0x%x)\n", i, frame.index,
                   static_cast<unsigned long long>(frame.data), check.problem.c_str(), check.errors);
    FUZZ_CHECK(check.errors == 0);
    FUZZ_CHECK(check.data == frame.data);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  if (references_png_file(text)) return 0;
  const scene::BuildOptions options;  // the simulator's 8 MiB of video memory
  auto parsed = scene::parse_scene(text, "fuzz.json", "/nonexistent-gpubridge-fuzz-dir");
  if (!parsed) {
    FUZZ_CHECK(parsed.error().message.rfind("fuzz.json:", 0) == 0);
    return 0;
  }
  auto built = scene::build_commands(*parsed, options);
  if (!built) {
    FUZZ_CHECK(built.error().message.rfind("fuzz.json", 0) == 0);
    return 0;
  }
  FUZZ_CHECK(built->width == parsed->width && built->height == parsed->height);
  FUZZ_CHECK(built->layout.end <= options.vram_bytes);
  FUZZ_CHECK(built->layout.textures.size() == parsed->textures.size());
  FUZZ_CHECK(!built->stream.commands.empty());
  std::size_t uploads = 0;
  for (const auto& timed : built->stream.commands) {
    FUZZ_CHECK(protocol::command_problem(timed.command).empty());
    if (const auto* f = std::get_if<protocol::FramesCmd>(&timed.command)) {
      check_frames(*f);
    } else if (const auto* u = std::get_if<protocol::UploadCmd>(&timed.command)) {
      FUZZ_CHECK(u->address + std::uint64_t{u->data.size()} <= built->layout.end);
      ++uploads;
    } else {
      FUZZ_CHECK(false && "a scene builds only register writes and uploads");
    }
  }
  FUZZ_CHECK(uploads == parsed->textures.size());
  const auto* last = std::get_if<protocol::FramesCmd>(&built->stream.commands.back().command);
  FUZZ_CHECK(last != nullptr);
  const protocol::Frame swap = last->view()[last->size() - 1];
  FUZZ_CHECK(swap.index == protocol::index_of(protocol::Reg::FB_DISPLAY));
  FUZZ_CHECK(swap.data == built->layout.color);
  return 0;
}
