#include "gpubridge/draw/client_sink.hpp"

#include <type_traits>

#include <nlohmann/json.hpp>

namespace gpubridge::draw {

ClientSink::ClientSink(client::Client& c) : client_(&c) {
  device_.vram_bytes = 8u << 20;
  const auto j = nlohmann::json::parse(c.session().device_json, nullptr, false);
  if (!j.is_object()) return;
  // Only well-typed values are taken; anything else keeps the default.
  const auto number = [&](const char* key, auto& field, std::uint64_t lo, std::uint64_t hi) {
    const auto it = j.find(key);
    if (it == j.end() || !it->is_number_unsigned()) return;
    const auto v = it->get<std::uint64_t>();
    if (v >= lo && v <= hi) field = static_cast<std::remove_reference_t<decltype(field)>>(v);
  };
  const auto text = [&](const char* key, std::string& field) {
    const auto it = j.find(key);
    if (it != j.end() && it->is_string()) field = it->get<std::string>();
  };
  number("vram_bytes", device_.vram_bytes, 1, ~std::uint64_t{0});
  number("max_width", device_.max_width, 1, protocol::kMaxFramebufferDim);
  number("max_height", device_.max_height, 1, protocol::kMaxFramebufferDim);
  number("caps", device_.caps, 0, ~std::uint64_t{0});
  number("caps2", device_.caps2, 0, ~std::uint64_t{0});  // from daemons of protocol 1.4 on
  number("id", device_.id, 0, ~std::uint64_t{0});
  text("backend", device_.backend);
  text("board", device_.board);
  text("bridge", device_.bridge);
}

Result<std::unique_ptr<ClientSink>> ClientSink::connect(std::string_view address, std::string_view name,
                                                        std::string_view token, client::Timeout timeout) {
  auto c = client::Client::connect(address, timeout);
  if (!c) return c.error();
  auto owned = std::make_unique<client::Client>(std::move(*c));
  if (auto h = owned->handshake(name, token, timeout); !h) return h.error();
  if (auto l = owned->acquire_lease(protocol::LeaseMode::Wait, timeout); !l) return l.error();
  auto sink = std::make_unique<ClientSink>(*owned);
  sink->owned_ = std::move(owned);
  return sink;
}

}  // namespace gpubridge::draw
