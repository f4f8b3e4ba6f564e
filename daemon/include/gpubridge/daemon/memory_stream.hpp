#pragma once
// An in-memory Stream: delivers a fixed input in caller-chosen chunks, then end-of-stream, and
// keeps what the session wrote. Lets tests and the fuzzer run the real Session dispatch without
// sockets (the completion handlers still run through the io_context, as with a socket).
#include <cstdint>
#include <algorithm>
#include <cstring>
#include <vector>

#include "gpubridge/daemon/stream.hpp"

namespace gpubridge::daemon {

class MemoryStream final : public Stream {
 public:
  // chunks: sizes of successive reads (cycled; 0 entries are treated as 1).
  MemoryStream(boost::asio::any_io_executor ex, std::vector<std::uint8_t> input, std::vector<std::size_t> chunks,
               std::vector<std::uint8_t>* output)
      : ex_(std::move(ex)), input_(std::move(input)), chunks_(std::move(chunks)), output_(output) {}

  void async_read_some(boost::asio::mutable_buffer buf, Handler handler) override {
    std::size_t n = 0;
    if (!closed_ && pos_ < input_.size()) {
      std::size_t want = chunks_.empty() ? input_.size() : std::max<std::size_t>(1, chunks_[chunk_++ % chunks_.size()]);
      n = std::min({want, buf.size(), input_.size() - pos_});
      std::memcpy(buf.data(), input_.data() + pos_, n);
      pos_ += n;
    }
    const auto ec = n ? boost::system::error_code{} : boost::system::error_code(boost::asio::error::eof);
    boost::asio::post(ex_, [handler = std::move(handler), ec, n] { handler(ec, n); });
  }
  void async_write(const std::vector<boost::asio::const_buffer>& bufs, Handler handler) override {
    std::size_t n = 0;
    for (const auto& b : bufs) {
      // Copy every byte so sanitizers see any read beyond a buffer the session handed us.
      const auto* p = static_cast<const std::uint8_t*>(b.data());
      if (output_ && output_->size() < (64u << 20)) output_->insert(output_->end(), p, p + b.size());
      n += b.size();
    }
    const auto ec = closed_ ? boost::system::error_code(boost::asio::error::broken_pipe) : boost::system::error_code{};
    boost::asio::post(ex_, [handler = std::move(handler), ec, n] { handler(ec, n); });
  }
  void close() override { closed_ = true; }
  std::string transport() const override { return "memory"; }
  std::string peer() const override { return "memory"; }

 private:
  boost::asio::any_io_executor ex_;
  std::vector<std::uint8_t> input_;
  std::vector<std::size_t> chunks_;
  std::size_t chunk_ = 0;
  std::size_t pos_ = 0;
  bool closed_ = false;
  std::vector<std::uint8_t>* output_;
};

}  // namespace gpubridge::daemon
