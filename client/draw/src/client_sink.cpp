#include "gpubridge/draw/client_sink.hpp"

#include <nlohmann/json.hpp>

namespace gpubridge::draw {

ClientSink::ClientSink(client::Client& c) : client_(&c) {
  const auto j = nlohmann::json::parse(c.session().device_json, nullptr, false);
  if (j.is_object() && j.contains("vram_bytes") && j["vram_bytes"].is_number_unsigned() && j["vram_bytes"].get<std::uint64_t>() > 0)
    vram_ = j["vram_bytes"].get<std::uint64_t>();
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
