#pragma once
// Where the viewer's frames come from. A source runs on its own thread and keeps only the newest
// frame (a slow display never holds up the producer: stale frames are dropped and counted). The
// display thread takes frames and reads the status without blocking; headless callers may wait.
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <mutex>
#include <optional>
#include <stop_token>
#include <string>
#include <thread>

#include "gpubridge/viewer/frame.hpp"

namespace gpubridge::viewer {

struct SourceStatus {
  enum class State {
    Connecting,  // first attempt in progress
    Streaming,   // connected and subscribed
    Waiting,     // lost the producer (daemon restarting); retrying
    Failed,      // cannot continue (wrong address, token refused): `message` says why
    Finished,    // the producer ended normally (test source with a frame limit)
  };
  State state = State::Connecting;
  std::string address;  // what the source reads from ("unix:/run/...", "test pattern")
  std::string backend;  // "sim", "usb", ... (empty until known)
  std::string board;    // board name when the backend has one
  std::string device;   // the device kind's label when it is not spigpu ("DMC-1"), else empty
  std::string frames_note;  // whose frames they are when not the device's own (a DMC-1 board: its simulator's)
  std::string accuracy;     // how the device renders (WELCOME "accuracy": exact, preview, knobs); empty if unknown
  std::string message;  // for Waiting/Failed: the last error, one line
  // Mirror mode (gpubridged --mirror): which picture is subscribed and how many swaps so far had a
  // board frame whose CRC differs from the simulator's (from the daemon's status).
  bool mirror = false;
  protocol::FrameSource picture = protocol::FrameSource::Board;
  std::optional<std::uint64_t> mismatches, compared;
  std::string picture_problem;  // why the last requested picture switch was refused
};
std::string_view to_string(SourceStatus::State s);
// "board", "simulator", "diff board vs simulator": what the window shows.
std::string picture_name(protocol::FrameSource s);

struct SourceCounters {
  std::uint64_t received = 0;  // frames handed to publish_frame
  std::uint64_t taken = 0;     // frames returned by take_newest
  std::uint64_t dropped = 0;   // frames replaced before anyone took them
  std::uint64_t rejected = 0;  // frames refused by frame_problem
  std::string last_rejection;  // why the last refused frame was refused
};

class FrameSource {
 public:
  FrameSource() = default;
  FrameSource(const FrameSource&) = delete;
  FrameSource& operator=(const FrameSource&) = delete;
  virtual ~FrameSource();

  // Starts the producer thread. on_change (optional) is called from that thread whenever a frame
  // or status arrives, e.g. to wake an event loop (glfwPostEmptyEvent); it must not block.
  void start(std::function<void()> on_change = {});
  // Asks the producer to stop and joins it. Idempotent; the destructor calls it too.
  void stop();

  // The newest frame not yet taken, if any.
  std::optional<Frame> take_newest();
  // Blocks until a frame is available, the status changed since `seen_status_version`, or timeout.
  // Returns true when something happened.
  bool wait(std::chrono::milliseconds timeout, std::uint64_t seen_status_version);
  SourceStatus status() const;
  std::uint64_t status_version() const;
  SourceCounters counters() const;
  // Asks the producer to switch pictures (B/M/D keys). Sources without pictures ignore it; the
  // daemon source resubscribes and reports the outcome in status().picture / picture_problem.
  void request_picture(protocol::FrameSource picture);

 protected:
  // Runs on the producer thread until stop is requested (or the producer gives up).
  virtual void run(std::stop_token stop) = 0;
  // Called by run(): hands over a frame (replacing an untaken one) / updates the status.
  void publish_frame(Frame frame);
  void publish_status(SourceStatus status);
  // Sleeps up to `d`, returning early (false) when stop is requested.
  bool sleep_for(std::stop_token stop, std::chrono::microseconds d);
  // The picture asked for with request_picture() since the last call, if any.
  std::optional<protocol::FrameSource> take_picture_request();

 private:
  void notify();

  mutable std::mutex mutex_;
  std::condition_variable_any changed_;
  std::optional<Frame> newest_;
  SourceStatus status_;
  std::uint64_t status_version_ = 0;
  SourceCounters counters_;
  std::optional<protocol::FrameSource> picture_request_;
  std::function<void()> on_change_;
  std::jthread thread_;
};

}  // namespace gpubridge::viewer
