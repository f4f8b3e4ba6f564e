#include "gpubridge/daemon/scanout_feed.hpp"

#include <cstdio>
#include <filesystem>

#include "gpubridge/common/image.hpp"
#include "gpubridge/common/log.hpp"
#include "gpubridge/daemon/frame_diff.hpp"

namespace gpubridge::daemon {

ScanoutFeed::ScanoutFeed(boost::asio::any_io_executor net, std::string frames_dir, std::function<void(Frame)> fan_out)
    : net_(std::move(net)), frames_dir_(std::move(frames_dir)), fan_out_(std::move(fan_out)) {}

void ScanoutFeed::stop() { stopped_ = true; }

MirrorStats ScanoutFeed::mirror_stats() const {
  std::lock_guard lock(mu_);
  return mirror_;
}

void ScanoutFeed::push(Frame frame) {
  if (stopped_) return;
  count_.fetch_add(1);
  last_number_ = frame->number;
  if (frame->reference) compare_mirrored(*frame);
  // A board whose profile says `"scanout": "crc"` reports the swap and its FRAME_CRC but no pixels:
  // count it, but never turn it into a blank PNG or a blank frame for subscribers. In mirror mode
  // the simulator's picture still goes to its subscribers.
  if (!frame->pixels.empty() && !frames_dir_.empty()) write_png(*frame);
  if (frame->pixels.empty() && !frame->reference) return;
  bool post = false;
  {
    std::lock_guard lock(mu_);
    post = !newest_;  // a hand-off already queued will take this newer swap instead
    newest_ = std::move(frame);
  }
  if (!post) return;
  boost::asio::post(net_, [this] {
    Frame f;
    {
      std::lock_guard lock(mu_);
      f = std::move(newest_);
      newest_.reset();
    }
    if (f && !stopped_) fan_out_(std::move(f));
  });
}

void ScanoutFeed::write_png(const backends::ScanoutFrame& frame) {
  char name[32];
  std::snprintf(name, sizeof name, "frame_%06u.png", frame.number);
  const auto path = std::filesystem::path(frames_dir_) / name;
  if (auto r = save_png(path, image_from_device(frame.format, frame.width, frame.height, frame.pixels)); !r)
    logger("daemon")->warn("frames dir: {}", r.error().message);
  else
    pngs_written_.fetch_add(1);
}

void ScanoutFeed::compare_mirrored(const backends::ScanoutFrame& frame) {
  // FRAME_CRC is the device's own CRC of the scanned-out bytes, so CRC-only boards compare too.
  if (frame.crc == frame.reference->crc) {
    std::lock_guard lock(mu_);
    ++mirror_.compared;
    return;
  }
  // Counting the differing pixels of every mismatch (not only the first) shows whether a fault
  // grows or stays put; it costs one pass over the frame, and only when the CRCs differ.
  std::optional<std::uint64_t> pixels;
  if (!frame.pixels.empty()) {
    std::uint64_t differing = 0;
    if (diff_frame(frame, *frame.reference, &differing)) pixels = differing;
  }
  bool first = false;
  {
    std::lock_guard lock(mu_);
    ++mirror_.compared;
    ++mirror_.mismatches;
    mirror_.last_mismatch = frame.number;
    mirror_.last_mismatch_pixels = pixels;
    if (!mirror_.first_mismatch) {
      first = true;
      mirror_.first_mismatch = frame.number;
      mirror_.first_mismatch_pixels = pixels;
    }
  }
  if (!first) return;
  const std::string where = pixels ? ", " + std::to_string(*pixels) + " pixels differ" : "";
  logger("daemon")->warn("mirror: frame {} differs from the simulator (board CRC 0x{:08X}, simulator CRC 0x{:08X}{}); "
                         "first mismatch, later ones are counted in status (mirror.mismatches)",
                         frame.number, frame.crc, frame.reference->crc, where);
}

}  // namespace gpubridge::daemon
