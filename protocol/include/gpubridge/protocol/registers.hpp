#pragma once
// The spigpu v1 register table: the single description that drives the frame encoder/decoder,
// register validation, the text-trace syntax and the table in docs/protocol.md
// (`gpubridge regs --markdown` prints it; a test checks the document matches).

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>

namespace gpubridge::protocol {

inline constexpr unsigned kRegisterCount = 128;  // 7-bit index space

// Register indices. Names match the table in registers.cpp and docs/protocol.md.
enum class Reg : std::uint8_t {
  COLOR = 0x00,
  TEXCOORD = 0x01,
  VERTEX = 0x02,
  PRIM = 0x03,
  TRI_MODE = 0x04,
  TEX_BASE = 0x05,
  TEX_FMT = 0x06,
  SCISSOR = 0x07,
  FB_DRAW = 0x08,
  FB_DISPLAY = 0x09,
  CLEAR_COLOR = 0x0A,
  CLEAR = 0x0B,
  CLEAR_Z = 0x0C,
  CLEAR_DEPTH = 0x0D,
  FB_Z = 0x0E,
  FB_FORMAT = 0x0F,
  STATUS = 0x10,
  ERR_CLEAR = 0x11,
  FRAME_CRC = 0x12,
  LINK_CTRL = 0x13,
  LINK_CHECK = 0x14,
  LINK_STATUS = 0x15,
  HOST_TAG = 0x16,
  RESET = 0x17,
  FENCE = 0x18,
  MEM_ADDR = 0x70,
  MEM_DATA = 0x71,
  CAPS2 = 0x7D,  // protocol 1.4: more capabilities (FEATURES2); undefined before
  CAPS = 0x7E,
  ID = 0x7F,
};

constexpr std::uint8_t index_of(Reg r) { return static_cast<std::uint8_t>(r); }

// Who may access a register over SPI.
enum class Access : std::uint8_t {
  ReadWrite,  // written through the command FIFO, read back as last executed value
  WriteOnly,  // command registers: reading returns 0 (no error)
  ReadOnly,   // writing is dropped and raises ERR_BAD_REGISTER
};

// How a write reaches the device core.
enum class Path : std::uint8_t {
  Queued,     // enters the command FIFO, executes in order
  Immediate,  // acted on by the SPI front end when the frame completes, bypassing the FIFO
};

enum class FieldKind : std::uint8_t {
  Unsigned,  // plain unsigned integer
  Signed,    // two's complement, width bits
  Flag,      // one bit
  Enum,      // unsigned with named values; values outside the list are BAD_VALUE
};

struct EnumValue {
  std::string_view name;
  std::uint32_t value;
};

struct Field {
  std::string_view name;
  std::uint8_t lsb;
  std::uint8_t width;
  FieldKind kind;
  std::span<const EnumValue> values;  // for Enum
  std::uint8_t frac_bits;             // fixed-point fraction bits (display only), 0 = integer
  std::string_view doc;

  constexpr std::uint64_t mask() const {
    return (width >= 64 ? ~0ull : ((1ull << width) - 1)) << lsb;
  }
  constexpr std::uint64_t get(std::uint64_t data) const {
    return (data & mask()) >> lsb;
  }
  // Sign-extended value for Signed fields, raw value otherwise.
  std::int64_t get_signed(std::uint64_t data) const;
  constexpr std::uint64_t put(std::uint64_t data, std::uint64_t v) const {
    return (data & ~mask()) | ((v << lsb) & mask());
  }
};

struct RegisterDesc {
  std::uint8_t index;
  std::string_view name;
  Access access;
  Path path;
  std::uint64_t reset;
  std::span<const Field> fields;
  std::string_view summary;

  // Bits not covered by any field: must be written as 0 (otherwise ignored + ERR_RESERVED_BITS).
  std::uint64_t reserved_mask() const;
  const Field* field(std::string_view field_name) const;  // case-insensitive
};

// All defined registers, in index order.
std::span<const RegisterDesc> register_table();
// nullptr for an undefined index or unknown name (names are case-insensitive).
const RegisterDesc* find_register(std::uint8_t index);
const RegisterDesc* find_register(std::string_view name);
const RegisterDesc& describe(Reg r);

// Enumerations shared by the device model, the host library and the text trace.
enum class PrimType : std::uint8_t { List = 0, Strip = 1, Fan = 2 };
enum class DepthFunc : std::uint8_t {
  Never = 0, Less = 1, Equal = 2, LessEqual = 3, Greater = 4, NotEqual = 5, GreaterEqual = 6, Always = 7
};
enum class BlendMode : std::uint8_t { Off = 0, Alpha = 1, Add = 2, Multiply = 3 };
enum class PixelFormat : std::uint8_t { RGBA8888 = 0, RGB565 = 1, RGBA2222 = 2 };
enum class Wrap : std::uint8_t { Repeat = 0, Clamp = 1, Mirror = 2 };

constexpr unsigned bytes_per_pixel(PixelFormat f) {
  return f == PixelFormat::RGBA8888 ? 4 : f == PixelFormat::RGB565 ? 2 : 1;
}
std::string_view to_string(PixelFormat f);
std::optional<PixelFormat> parse_pixel_format(std::string_view s);

// STATUS.ERRORS bits (also ERR_CLEAR mask bits).
enum ErrorFlag : std::uint16_t {
  ERR_FRAMING = 1u << 0,        // chip select rose inside a frame; partial frame discarded
  ERR_OVERFLOW = 1u << 1,       // queued write arrived with the FIFO full; write dropped
  ERR_LINK_CRC = 1u << 2,       // LINK_CHECK value did not match the device's CRC
  ERR_RESERVED_BITS = 1u << 3,  // a write had reserved bits set; they were ignored
  ERR_BAD_VALUE = 1u << 4,      // a field value out of range; replaced as documented
  ERR_BAD_REGISTER = 1u << 5,   // access to an undefined register or write to a read-only one
  ERR_MEM_RANGE = 1u << 6,      // memory access beyond VRAM; write dropped / read as 0
};
inline constexpr std::uint16_t kAllErrors = 0x7F;
std::string describe_errors(std::uint16_t flags);  // "FRAMING|LINK_CRC" or "none"

// The status byte the device shifts out on MISO during bits [71:64] of every frame.
enum MisoStatus : std::uint8_t {
  MISO_MARKER = 0x80,        // bit 7 = 1, bit 6 = 0 always: 0xFF / 0x00 mean "no device"
  MISO_MARKER_MASK = 0xC0,
  MISO_FIFO_NEARLY_FULL = 1u << 5,
  MISO_ERROR = 1u << 4,
  MISO_BUSY = 1u << 3,
  MISO_VBLANK = 1u << 2,
  MISO_SWAP_PENDING = 1u << 1,
  MISO_MEM_READY = 1u << 0,
};
constexpr bool miso_status_valid(std::uint8_t b) { return (b & MISO_MARKER_MASK) == MISO_MARKER; }

// Fixed identification values.
inline constexpr std::uint32_t kIdMagic = 0x53504755;  // "SPGU" in ID[63:32]
inline constexpr std::uint8_t kVersionMajor = 1;
// 1.1: TRI_MODE.TEMPORAL / DITHER_PHASE; 1.2: CAPS.FEATURES bit 7 (texturing); 1.3: LINK_CTRL.CLEAR_KEY;
// 1.4: CAPS2 (0x7D), FEATURES2 bit 0 = depth buffer.
inline constexpr std::uint8_t kVersionMinor = 4;
inline constexpr std::uint64_t kResetMagic = 0x5245534554ull;  // "RESET": RESET's required data
// "off!" in LINK_CTRL.CLEAR_KEY: a LINK_CTRL write with STRICT = 0 leaves strict mode only with it
// (protocol 1.3, docs/protocol.md section 4), so no single bit error can turn strict mode off.
inline constexpr std::uint32_t kLinkClearKey = 0x6F666621;
// ID's fields (docs/protocol.md section 5): MAGIC [63:32], MAJOR [31:24], MINOR [23:16], VARIANT [15:0].
constexpr unsigned protocol_major(std::uint64_t id) { return static_cast<unsigned>((id >> 24) & 0xFF); }
constexpr unsigned protocol_minor(std::uint64_t id) { return static_cast<unsigned>((id >> 16) & 0xFF); }
constexpr unsigned id_variant(std::uint64_t id) { return static_cast<unsigned>(id & 0xFFFF); }
// The LINK_CTRL data that leaves strict mode on the device whose ID register reads `id`: the key
// from 1.3 on; 0 before, where the key's bits are reserved (a 1.2 device would flag them).
constexpr std::uint64_t link_ctrl_clear_value(std::uint64_t id) {
  return protocol_minor(id) >= 3 ? std::uint64_t{kLinkClearKey} << 32 : 0;
}
// CAPS2.FEATURES2 bits (protocol 1.4, docs/protocol.md section 5, CAPS2).
inline constexpr std::uint8_t kFeature2Depth = 1u << 0;  // depth buffer: TRI_MODE.Z_TEST/Z_WRITE, CLEAR_Z
// Whether the device whose ID reads `id` and CAPS2 reads `caps2` has a depth buffer. CAPS2 exists
// from 1.4 on; every 1.0 ... 1.3 device has one (its CAPS2 index is undefined: a host does not read
// it there, and passes 0).
constexpr bool has_depth_buffer(std::uint64_t id, std::uint64_t caps2) {
  return protocol_minor(id) < 4 || (caps2 & kFeature2Depth) != 0;
}
inline constexpr unsigned kMaxFramebufferDim = 1024;
inline constexpr unsigned kMinTextureLog2 = 3;
inline constexpr unsigned kMaxTextureLog2 = 10;

// Result of validating one register write against the table.
struct WriteCheck {
  std::uint64_t data;   // value with reserved bits cleared and out-of-range fields replaced
  std::uint16_t errors; // ERR_* flags the device latches for this write (0 = clean)
  std::string problem;  // human-readable reason when errors != 0
};
// Applies the table's reserved-bit and enum rules (register-specific range rules live in the
// device model and are documented per register). Unknown index → ERR_BAD_REGISTER.
WriteCheck check_write(std::uint8_t index, std::uint64_t data);

}  // namespace gpubridge::protocol
