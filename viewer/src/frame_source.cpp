#include "gpubridge/viewer/frame_source.hpp"

namespace gpubridge::viewer {

std::string_view to_string(SourceStatus::State s) {
  switch (s) {
    case SourceStatus::State::Connecting: return "connecting";
    case SourceStatus::State::Streaming: return "streaming";
    case SourceStatus::State::Waiting: return "waiting";
    case SourceStatus::State::Failed: return "failed";
    case SourceStatus::State::Finished: return "finished";
  }
  return "?";
}

std::string picture_name(protocol::FrameSource s) {
  switch (s) {
    case protocol::FrameSource::Board: return "board";
    case protocol::FrameSource::Sim: return "simulator";
    case protocol::FrameSource::Diff: return "diff board vs simulator";
  }
  return "?";
}

FrameSource::~FrameSource() {
  // Derived classes must call stop() in their own destructor (run() uses their members); this
  // is the safety net for sources that were never started.
  stop();
}

void FrameSource::start(std::function<void()> on_change) {
  on_change_ = std::move(on_change);
  thread_ = std::jthread([this](std::stop_token stop) { run(stop); });
}

void FrameSource::stop() {
  if (thread_.joinable()) {
    thread_.request_stop();
    changed_.notify_all();
    thread_.join();
  }
}

std::optional<Frame> FrameSource::take_newest() {
  std::lock_guard lock(mutex_);
  std::optional<Frame> out;
  out.swap(newest_);
  if (out) ++counters_.taken;
  return out;
}

bool FrameSource::wait(std::chrono::milliseconds timeout, std::uint64_t seen_status_version) {
  std::unique_lock lock(mutex_);
  return changed_.wait_for(lock, timeout,
                           [&] { return newest_.has_value() || status_version_ != seen_status_version; });
}

SourceStatus FrameSource::status() const {
  std::lock_guard lock(mutex_);
  return status_;
}

std::uint64_t FrameSource::status_version() const {
  std::lock_guard lock(mutex_);
  return status_version_;
}

SourceCounters FrameSource::counters() const {
  std::lock_guard lock(mutex_);
  return counters_;
}

void FrameSource::publish_frame(Frame frame) {
  {
    std::lock_guard lock(mutex_);
    ++counters_.received;
    if (auto problem = frame_problem(frame); !problem.empty()) {
      ++counters_.rejected;
      counters_.last_rejection = std::move(problem);
      return;
    }
    if (newest_) ++counters_.dropped;
    newest_ = std::move(frame);
  }
  notify();
}

void FrameSource::publish_status(SourceStatus status) {
  {
    std::lock_guard lock(mutex_);
    status_ = std::move(status);
    ++status_version_;
  }
  notify();
}

void FrameSource::request_picture(protocol::FrameSource picture) {
  {
    std::lock_guard lock(mutex_);
    picture_request_ = picture;
  }
  notify();  // the producer picks it up at its next poll (at most a few hundred ms)
}

std::optional<protocol::FrameSource> FrameSource::take_picture_request() {
  std::lock_guard lock(mutex_);
  std::optional<protocol::FrameSource> out;
  out.swap(picture_request_);
  return out;
}

bool FrameSource::sleep_for(std::stop_token stop, std::chrono::microseconds d) {
  std::unique_lock lock(mutex_);
  changed_.wait_for(lock, stop, d, [] { return false; });
  return !stop.stop_requested();
}

void FrameSource::notify() {
  changed_.notify_all();
  if (on_change_) on_change_();
}

}  // namespace gpubridge::viewer
