// The asynchronous half of the libusb binding. The synchronous API cannot read while a bulk OUT
// is pending, so an FTDI MPSSE whose reads outgrow its RX FIFO would stall the OUT forever; here
// the IN transfers are queued before the commands go out and are re-queued as they complete.
#include "libusb_stream.hpp"

#include <chrono>
#include <deque>
#include <vector>

#include "gpubridge/common/log.hpp"
#include "libusb_status.hpp"

namespace gpubridge::usb {
namespace {

// One libusb transfer and its buffer; `completed` is set by the callback and consumed by the loop,
// so all decisions happen in one place, outside libusb's callback.
struct Slot {
  libusb_transfer* transfer = nullptr;
  std::vector<unsigned char> buffer;
  bool flying = false;
  bool completed = false;
};

void LIBUSB_CALL on_transfer_done(libusb_transfer* t) {
  auto* slot = static_cast<Slot*>(t->user_data);
  slot->flying = false;
  slot->completed = true;
}

class Stream {
 public:
  Stream(libusb_context* ctx, libusb_device_handle* h, const BulkStream& s, const UsbDevice::InSink& on_in)
      : ctx_(ctx), h_(h), s_(s), on_in_(on_in), in_(s.in_queue_depth == 0 ? 1 : s.in_queue_depth) {}

  ~Stream() {
    cancel_and_reap();
    for (Slot* slot : all_slots())
      if (slot->transfer && !slot->flying) libusb_free_transfer(slot->transfer);
  }

  BulkStreamResult run() {
    for (Slot* slot : all_slots()) {
      slot->transfer = libusb_alloc_transfer(0);
      if (!slot->transfer) return fail(UsbStatus::NoMem);
    }
    for (Slot& slot : in_) {
      slot.buffer.resize(s_.in_transfer_bytes);
      if (auto st = submit_in(slot); st != UsbStatus::Ok) return fail(st);
    }
    if (auto st = submit_next_out(); st != UsbStatus::Ok) return fail(st);
    auto last_progress = std::chrono::steady_clock::now();
    while (res_.out_transferred < s_.out.size() || !consumer_done_) {
      timeval tv{0, 50'000};
      if (const int rc = libusb_handle_events_timeout_completed(ctx_, &tv, nullptr); rc < 0 && rc != LIBUSB_ERROR_INTERRUPTED)
        return fail(status_of(rc));
      bool progressed = false;
      if (out_.completed) {
        out_.completed = false;
        progressed = true;
        ++res_.out_transfers;
        res_.out_transferred += static_cast<std::size_t>(out_.transfer->actual_length);
        if (const UsbStatus st = status_of_transfer(out_.transfer->status); st != UsbStatus::Ok) return fail(st);
        if (auto st = submit_next_out(); st != UsbStatus::Ok) return fail(st);
      }
      // IN transfers on one endpoint complete in submission order; hand them over in that order.
      while (!in_order_.empty() && in_order_.front()->completed) {
        Slot& slot = *in_order_.front();
        in_order_.pop_front();
        slot.completed = false;
        progressed = true;
        ++res_.in_transfers;
        if (consumer_done_) continue;  // everything expected has arrived; leftovers do not matter
        if (const UsbStatus st = status_of_transfer(slot.transfer->status); st != UsbStatus::Ok) return fail(st);
        const auto got = std::span<const std::uint8_t>(slot.buffer).first(static_cast<std::size_t>(slot.transfer->actual_length));
        const StreamStep step = on_in_(got);
        if (step == StreamStep::Abort) return res_;
        if (step == StreamStep::Done) {
          consumer_done_ = true;
          continue;
        }
        if (auto st = submit_in(slot); st != UsbStatus::Ok) return fail(st);
      }
      const auto now = std::chrono::steady_clock::now();
      if (progressed) last_progress = now;
      else if (now - last_progress > std::chrono::milliseconds(s_.timeout_ms)) return fail(UsbStatus::Timeout);
    }
    return res_;
  }

 private:
  std::vector<Slot*> all_slots() {
    std::vector<Slot*> v{&out_};
    for (Slot& slot : in_) v.push_back(&slot);
    return v;
  }

  BulkStreamResult fail(UsbStatus st) {
    res_.status = st;
    return res_;
  }

  UsbStatus submit(Slot& slot, unsigned char endpoint, unsigned char* data, std::size_t length) {
    // No per-transfer timeout: the loop's inactivity timeout covers the whole stream.
    libusb_fill_bulk_transfer(slot.transfer, h_, endpoint, data, static_cast<int>(length), on_transfer_done, &slot, 0);
    const int rc = libusb_submit_transfer(slot.transfer);
    if (rc < 0) return status_of(rc);
    slot.flying = true;
    return UsbStatus::Ok;
  }

  UsbStatus submit_in(Slot& slot) {
    const UsbStatus st = submit(slot, s_.in_endpoint, slot.buffer.data(), slot.buffer.size());
    if (st == UsbStatus::Ok) in_order_.push_back(&slot);
    return st;
  }

  UsbStatus submit_next_out() {
    if (out_sent_ >= s_.out.size()) return UsbStatus::Ok;
    const std::size_t n = std::min(s_.out_chunk, s_.out.size() - out_sent_);
    // libusb takes a non-const buffer for both directions; OUT data is only read.
    auto* data = const_cast<unsigned char*>(s_.out.data() + out_sent_);
    out_sent_ += n;
    return submit(out_, s_.out_endpoint, data, n);
  }

  // Cancelled transfers still complete (CANCELLED or NO_DEVICE) and must be reaped before their
  // memory goes away; libusb guarantees that, so this waits, with a generous bound as a backstop.
  void cancel_and_reap() {
    for (Slot* slot : all_slots())
      if (slot->flying) libusb_cancel_transfer(slot->transfer);
    const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(5);
    for (;;) {
      bool any = false;
      for (Slot* slot : all_slots()) any = any || slot->flying;
      if (!any) return;
      if (std::chrono::steady_clock::now() > give_up) {
        // Freeing a transfer libusb still owns would be a use-after-free; leaking it is the lesser evil.
        logger("usb")->error("libusb did not return cancelled transfers within 5 s; leaking them");
        for (Slot* slot : all_slots())
          if (slot->flying) slot->transfer = nullptr;
        return;
      }
      timeval tv{0, 100'000};
      libusb_handle_events_timeout_completed(ctx_, &tv, nullptr);
    }
  }

  libusb_context* ctx_;
  libusb_device_handle* h_;
  const BulkStream& s_;
  const UsbDevice::InSink& on_in_;
  Slot out_;
  std::vector<Slot> in_;
  std::deque<Slot*> in_order_;
  std::size_t out_sent_ = 0;
  bool consumer_done_ = false;
  BulkStreamResult res_;
};

}  // namespace

BulkStreamResult run_libusb_stream(libusb_context* ctx, libusb_device_handle* handle, const BulkStream& s,
                                   const UsbDevice::InSink& on_in) {
  if (s.out_chunk == 0 || s.in_transfer_bytes == 0 || s.in_transfer_bytes > (1u << 24) || s.out_chunk > (1u << 24))
    return {UsbStatus::InvalidParam, 0, 0, 0};
  Stream stream(ctx, handle, s, on_in);
  return stream.run();
}

}  // namespace gpubridge::usb
