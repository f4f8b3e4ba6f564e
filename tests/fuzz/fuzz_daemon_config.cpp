// Fuzzes the daemon configuration: the input is parsed as JSON the way load_config does (comments
// allowed; text that is not JSON is load_config's own error and stops here), then parse_config and,
// when the config names no token_file (finalize_config would read that path), finalize_config.
// Properties: refusals name the source; an accepted config holds only values in the documented
// ranges, and a finalized one listens somewhere with addresses that parse.
#include <string_view>

#include <nlohmann/json.hpp>

#include "fuzz_check.hpp"
#include "gpubridge/client/address.hpp"
#include "gpubridge/daemon/config.hpp"
#include "gpubridge/protocol/messages.hpp"

using namespace gpubridge;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const auto doc = nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false, /*ignore_comments=*/true);
  if (doc.is_discarded()) return 0;
  auto cfg = daemon::parse_config(doc, "fuzz.json");
  if (!cfg) {
    FUZZ_CHECK(cfg.error().message.rfind("fuzz.json: ", 0) == 0);
    return 0;
  }
  const auto& lim = cfg->limits;
  FUZZ_CHECK(!cfg->backend.empty());
  FUZZ_CHECK(cfg->reattach_interval_ms <= daemon::kMaxReattachIntervalMs);
  FUZZ_CHECK(lim.max_message_bytes >= 4096 && lim.max_message_bytes <= protocol::kMaxPayload);
  FUZZ_CHECK(lim.max_clients >= 1 && lim.max_clients <= 4096);
  FUZZ_CHECK(lim.max_pending_handshakes >= 1 && lim.max_pending_handshakes <= 4096);
  FUZZ_CHECK(lim.handshake_timeout_ms >= 10 && lim.handshake_timeout_ms <= 600000);
  FUZZ_CHECK(lim.idle_timeout_ms <= 86400000);
  FUZZ_CHECK(lim.trickle_window_ms >= 10 && lim.trickle_window_ms <= 600000);
  FUZZ_CHECK(lim.min_bytes_per_sec <= (1u << 30));
  FUZZ_CHECK(lim.queue_bytes >= (1u << 20) && lim.queue_bytes <= (1ull << 32));
  for (const auto& l : cfg->listen) FUZZ_CHECK(client::parse_address(l).ok());
  if (!cfg->token_file.empty()) return 0;
  daemon::DaemonConfig finalized = *cfg;
  auto fin = daemon::finalize_config(finalized);
  if (!fin) {
    FUZZ_CHECK(!fin.error().message.empty());
    return 0;
  }
  FUZZ_CHECK(!finalized.listen.empty());
  FUZZ_CHECK(finalized.token.size() <= protocol::kMaxTokenBytes);
  return 0;
}
