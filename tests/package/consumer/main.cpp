// Talks to a running gpubridged through the installed client library: handshake, lease, a register
// echo through HOST_TAG and an upload/readback round trip. Exit 0 only when every step checks out.
#include <cstdio>
#include <cstdint>
#include <vector>

#include "gpubridge/client/client.hpp"

namespace gc = gpubridge::client;
namespace gp = gpubridge::protocol;

static int fail(const char* step, const gpubridge::Error& e) {
  std::fprintf(stderr, "consumer: %s failed: %s\n", step, e.message.c_str());
  return 1;
}

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: consumer unix:PATH\n");
    return 2;
  }
  auto client = gc::Client::connect(argv[1]);
  if (!client.ok()) return fail("connect", client.error());
  auto session = client->handshake("package-consumer");
  if (!session.ok()) return fail("handshake", session.error());
  if (auto r = client->acquire_lease(); !r.ok()) return fail("lease", r.error());

  const std::uint64_t tag = 0x00C0FFEE12345678ull;
  gc::RegisterWriter writer(*client);
  if (auto r = writer.write(gp::Reg::HOST_TAG, tag); !r.ok()) return fail("write", r.error());
  if (auto r = writer.flush(); !r.ok()) return fail("flush", r.error());
  if (auto r = client->fence(); !r.ok()) return fail("fence", r.error());
  auto echoed = client->read_register(gp::index_of(gp::Reg::HOST_TAG));
  if (!echoed.ok()) return fail("read HOST_TAG", echoed.error());
  if (*echoed != tag) {
    std::fprintf(stderr, "consumer: HOST_TAG read back 0x%llx, wrote 0x%llx\n",
                 static_cast<unsigned long long>(*echoed), static_cast<unsigned long long>(tag));
    return 1;
  }

  std::vector<std::uint8_t> bytes(4096);
  for (std::size_t i = 0; i < bytes.size(); ++i) bytes[i] = static_cast<std::uint8_t>(i * 7 + 3);
  if (auto r = client->upload(0x10000, bytes); !r.ok()) return fail("upload", r.error());
  auto back = client->readback(0x10000, static_cast<std::uint32_t>(bytes.size()));
  if (!back.ok()) return fail("readback", back.error());
  if (*back != bytes) {
    std::fprintf(stderr, "consumer: readback differs from the upload\n");
    return 1;
  }
  std::printf("consumer: ok (session %u)\n", session->session_id);
  return 0;
}
