// The device: SPI front end (link CRC, strict mode, immediate registers, reads), command FIFO,
// register file with its validation rules, primitive assembly, clears, memory access and swaps.
// Rendering itself is the Renderer's (setup → rasteriser → texture unit → pixel pipeline).
#include "gpubridge/sim/device.hpp"

#include <algorithm>
#include <array>
#include <deque>

#include "draw_state.hpp"
#include "fixed_point.hpp"
#include "gpubridge/protocol/crc32.hpp"
#include "gpubridge/protocol/pixel.hpp"
#include "renderer.hpp"
#include "scanout.hpp"
#include "setup.hpp"
#include "video_memory.hpp"

namespace gpubridge::sim {

using namespace protocol;

namespace {

constexpr std::size_t kCrcBufferBytes = 4096 - 4096 % kFrameBytes;

struct FifoEntry {
  std::uint8_t index;
  std::uint64_t data;
};

// Per-index facts needed on the hot path, so valid writes skip the general validator.
struct RegisterFacts {
  std::array<std::uint64_t, kRegisterCount> reserved{};
  std::array<bool, kRegisterCount> has_enum{};
  std::array<const RegisterDesc*, kRegisterCount> desc{};  // null: no register at that index
  // By a frame's first byte (R/W̄ and index): writes to the per-vertex registers, whose whole
  // validation is their reserved bits (no enumeration, no range rule) and whose execution only
  // latches them (VERTEX also assembles). Most frames of a drawing stream are these.
  std::array<bool, 256> vertex_write{};
  RegisterFacts() {
    for (const auto& r : register_table()) {
      desc[r.index] = &r;
      reserved[r.index] = r.reserved_mask();
      for (const auto& f : r.fields) has_enum[r.index] = has_enum[r.index] || f.kind == FieldKind::Enum;
    }
    for (const Reg r : {Reg::COLOR, Reg::TEXCOORD, Reg::VERTEX})
      vertex_write[index_of(r)] = !has_enum[index_of(r)] && desc[index_of(r)]->path == Path::Queued;
  }
};

std::uint64_t make_caps(const DeviceOptions& o) {
  return (std::uint64_t{o.features} << 56) | (std::uint64_t{o.fifo_depth} << 46) |
         (std::uint64_t{o.max_height} << 35) | (std::uint64_t{o.max_width} << 24) | (o.vram_bytes / 1024);
}

}  // namespace

struct Device::State {
  explicit State(const DeviceOptions& o)
      : opt(o),
        caps(make_caps(o)),
        caps2(o.features2),
        id((std::uint64_t{kIdMagic} << 32) | (std::uint64_t{kVersionMajor} << 24) |
           (std::uint64_t{kVersionMinor} << 16) | o.variant),
        mem(o.vram_bytes),
        renderer(mem, o.accuracy, o.threads, o.vector_routines, o.sdram_rows) {
    reset_registers();
  }

  DeviceOptions opt;
  std::uint64_t caps, caps2, id;
  RegisterFacts facts;
  VideoMemory mem;
  Renderer renderer;
  Scanout scanout;
  backends::ScanoutCallback scanout_cb;
  DeviceStats stats;

  std::array<std::uint64_t, kRegisterCount> regs{};
  std::uint16_t errors = 0;
  std::uint64_t host_tag = 0;
  // Command FIFO: the last `held` entries wait for a LINK_CHECK (strict mode).
  std::deque<FifoEntry> fifo;
  std::size_t held = 0;
  std::uint64_t frame_tick = 0;
  // Link integrity.
  std::uint32_t link_crc = 0;  // zlib-convention running CRC of the frames folded in so far
  // Frames not yet folded into link_crc (folded 4 KiB at a time: zlib is fast on long runs).
  std::array<std::uint8_t, kCrcBufferBytes> crc_buffer{};
  std::size_t crc_fill = 0;
  std::uint32_t link_frames = 0;
  bool strict = false, discarding = false, group_failed = false;
  std::uint16_t groups_ok = 0, groups_bad = 0;
  // Memory access.
  std::uint64_t prefetch = 0;
  bool prefetch_beyond = false;
  bool mem_ready = false;
  // Primitive assembly.
  Vertex stored[2];
  unsigned vertex_count = 0;
  std::uint64_t triangles = 0;
  std::shared_ptr<const DrawState> state;

  void reset_registers() {
    for (const auto& r : register_table()) regs[r.index] = r.reset;
    state.reset();
  }

  // --- link CRC ---
  void feed_crc(const Frame& f) {
    std::uint8_t* b = crc_buffer.data() + crc_fill;  // the frame's wire bytes (frame.hpp)
    b[0] = static_cast<std::uint8_t>((f.read ? 0x80 : 0) | f.index);
    store_be64(b + 1, f.data);
    crc_fill += kFrameBytes;
    if (crc_fill >= kCrcBufferBytes) fold_crc();
    link_frames = (link_frames + 1) & 0xFFFFFF;
  }
  // A run of frames [begin, end) of the caller's buffer that write_frames() executed at once as
  // vertex writes: their bytes join the link CRC and they are counted (frames received, FIFO
  // entries executed, LINK_STATUS.FRAMES) as frame() and execute() count each.
  void take_run(const std::uint8_t* begin, const std::uint8_t* end) {
    if (begin == end) return;
    fold_crc();
    link_crc = crc32_update(link_crc, std::span<const std::uint8_t>(begin, end));
    const auto n = static_cast<std::size_t>(end - begin) / kFrameBytes;
    stats.frames_received += n;
    stats.queued_executed += n;
    link_frames = static_cast<std::uint32_t>((link_frames + n) & 0xFFFFFF);
  }
  void fold_crc() {
    link_crc = crc32_update(link_crc, std::span<const std::uint8_t>(crc_buffer.data(), crc_fill));
    crc_fill = 0;
  }
  void restart_link_group() {
    crc_fill = 0;
    link_crc = 0;
    link_frames = 0;
    group_failed = false;
  }

  // --- errors from the renderer ---
  std::uint16_t current_errors() {
    errors |= renderer.take_errors();
    return errors;
  }

  const DrawState& draw_state() {
    if (!state) {
      const RegisterValues rv{regs[index_of(Reg::TRI_MODE)], regs[index_of(Reg::TEX_BASE)],
                              regs[index_of(Reg::TEX_FMT)],  regs[index_of(Reg::SCISSOR)],
                              regs[index_of(Reg::FB_DRAW)],  regs[index_of(Reg::FB_Z)],
                              regs[index_of(Reg::FB_FORMAT)]};
      state = std::make_shared<const DrawState>(decode_draw_state(rv, mem.size()));
    }
    return *state;
  }

  // --- validation (section 5) ---
  // Returns the data to act on; sets the error flags of the write.
  std::uint64_t validate(std::uint8_t index, std::uint64_t data) {
    if ((data & facts.reserved[index]) || facts.has_enum[index]) {
      const WriteCheck c = check_write(index, data);
      errors |= c.errors;
      data = c.data;
    }
    auto bad = [&] { errors |= ERR_BAD_VALUE; };
    auto need = [&](std::uint8_t feature, std::uint64_t field_mask) {
      if ((data & field_mask) && !(opt.features & feature)) {
        data &= ~field_mask;
        bad();
      }
    };
    switch (static_cast<Reg>(index)) {
      case Reg::TEX_FMT: {
        for (unsigned shift : {0u, 4u}) {
          const unsigned v = (data >> shift) & 15;
          const unsigned c = std::clamp<unsigned>(v, kMinTextureLog2, kMaxTextureLog2);
          if (c != v) {
            data = (data & ~(std::uint64_t{15} << shift)) | (std::uint64_t{c} << shift);
            bad();
          }
        }
        need(FEATURE_BILINEAR, 1ull << 12);
        const auto fmt = (data >> 16) & 3;
        if ((fmt == 1 && !(opt.features & FEATURE_RGB565)) || (fmt == 2 && !(opt.features & FEATURE_RGBA2222))) {
          data &= ~(3ull << 16);
          bad();
        }
        break;
      }
      case Reg::FB_FORMAT: {
        const std::uint64_t w = data & 0x7FF, h = (data >> 16) & 0x7FF;
        const std::uint64_t cw = std::clamp<std::uint64_t>(w, 1, opt.max_width);
        const std::uint64_t ch = std::clamp<std::uint64_t>(h, 1, opt.max_height);
        if (cw != w || ch != h) bad();
        data = (data & ~0x07FF07FFull) | cw | (ch << 16);
        const auto fmt = (data >> 32) & 3;
        if ((fmt == 1 && !(opt.features & FEATURE_RGB565)) || (fmt == 2 && !(opt.features & FEATURE_RGBA2222))) {
          data &= ~(3ull << 32);
          bad();
        }
        break;
      }
      case Reg::SCISSOR:
        for (unsigned shift : {0u, 16u, 32u, 48u}) {
          if (((data >> shift) & 0x7FF) > kMaxFramebufferDim) {
            data = (data & ~(0x7FFull << shift)) | (std::uint64_t{kMaxFramebufferDim} << shift);
            bad();
          }
        }
        break;
      case Reg::TRI_MODE:
        need(FEATURE_TEXTURE, 1ull << 1);
        need(FEATURE_BLEND, 3ull << 7);
        need(FEATURE_DITHER, 1ull << 9);
        need(FEATURE_TEMPORAL_DITHER, (1ull << 15) | (15ull << 16));  // TEMPORAL, DITHER_PHASE
        // No depth buffer (CAPS2.FEATURES2 bit 0, protocol 1.4): Z_TEST and Z_WRITE read as 0;
        // Z_FUNC stays as written (without Z_TEST it decides nothing).
        if ((data & ((1ull << 2) | (1ull << 6))) && !(opt.features2 & FEATURE2_DEPTH)) {
          data &= ~((1ull << 2) | (1ull << 6));
          bad();
        }
        break;
      case Reg::LINK_CTRL: need(FEATURE_STRICT_LINK, 1); break;
      default: break;
    }
    return data;
  }

  // --- queued commands ---
  // The effect of a write that arrives while the device executes queued writes at once (below)
  // on a register facts.vertex_write names: execute() without its general validation and dispatch
  // (and without its count: take_run() counts a whole run).
  void execute_vertex_write(std::uint8_t index, std::uint64_t data) {
    if (data & facts.reserved[index]) {  // validate(): rule 2 is the only one these registers have
      errors |= ERR_RESERVED_BITS;
      data &= ~facts.reserved[index];
    }
    regs[index] = data;
    if (index == index_of(Reg::VERTEX)) push_vertex(data);
  }

  void execute(const FifoEntry& e) {
    ++stats.queued_executed;
    const std::uint64_t data = validate(e.index, e.data);
    regs[e.index] = data;
    switch (static_cast<Reg>(e.index)) {
      case Reg::VERTEX: push_vertex(data); break;
      case Reg::PRIM: vertex_count = 0; break;
      case Reg::TRI_MODE:
      case Reg::TEX_BASE:
      case Reg::TEX_FMT:
      case Reg::SCISSOR:
      case Reg::FB_DRAW:
      case Reg::FB_Z:
      case Reg::FB_FORMAT: state.reset(); break;
      case Reg::CLEAR: clear_color(); break;
      case Reg::CLEAR_Z:  // refused when it executes on a device without a depth buffer (section 5, rule 5)
        if (opt.features2 & FEATURE2_DEPTH)
          clear_depth();
        else
          errors |= ERR_BAD_VALUE;
        break;
      case Reg::FB_DISPLAY: swap(data); break;
      case Reg::MEM_ADDR: load_prefetch(); break;
      case Reg::MEM_DATA: write_mem_data(data); break;
      default: break;  // latched registers (COLOR, TEXCOORD, CLEAR_COLOR, CLEAR_DEPTH, FENCE)
    }
  }

  void run_released(std::size_t limit) {
    while (limit-- > 0 && fifo.size() > held) {
      const FifoEntry e = fifo.front();
      fifo.pop_front();
      execute(e);
    }
  }
  bool untimed() const { return opt.fifo_drain_per_frame == 0; }

  void push_vertex(std::uint64_t data) {
    Vertex v;
    v.x = static_cast<std::int16_t>(data & 0xFFFF);
    v.y = static_cast<std::int16_t>((data >> 16) & 0xFFFF);
    v.z = static_cast<std::uint32_t>((data >> 32) & 0xFFFFFF);
    const std::uint64_t col = regs[index_of(Reg::COLOR)], tc = regs[index_of(Reg::TEXCOORD)];
    v.c[0] = static_cast<std::uint8_t>(col >> 24);
    v.c[1] = static_cast<std::uint8_t>(col >> 16);
    v.c[2] = static_cast<std::uint8_t>(col >> 8);
    v.c[3] = static_cast<std::uint8_t>(col);
    v.q = static_cast<std::uint32_t>(col >> 32);
    v.s = static_cast<std::int32_t>(static_cast<std::uint32_t>(tc >> 32));
    v.t = static_cast<std::int32_t>(static_cast<std::uint32_t>(tc));
    const auto type = static_cast<PrimType>(regs[index_of(Reg::PRIM)] & 3);
    if (vertex_count < 2) {
      stored[vertex_count++] = v;
      return;
    }
    kick(stored[0], stored[1], v);
    switch (type) {
      case PrimType::Strip:
        stored[0] = stored[1];
        stored[1] = v;
        break;
      case PrimType::Fan: stored[1] = v; break;
      default: vertex_count = 0; break;
    }
  }

  void kick(const Vertex& a, const Vertex& b, const Vertex& c) {
    ++stats.triangles_kicked;
    draw_state();
    renderer.draw(a, b, c, state, triangles++);
  }

  // --- clears (section 12) ---
  void fill_rect(std::uint32_t base, unsigned bpp, const std::uint8_t* value) {
    const DrawState& st = draw_state();
    if (st.clip.empty()) return;
    renderer.flush();
    const unsigned cols = static_cast<unsigned>(st.clip.x1 - st.clip.x0);
    std::vector<std::uint8_t> row(std::size_t{cols} * bpp);
    for (unsigned i = 0; i < cols; ++i) std::copy(value, value + bpp, row.begin() + std::size_t{i} * bpp);
    bool dropped = false;
    ++stats.clears;
    renderer.texel_cache().invalidate();  // the core forgets its texels after another command
    stats.clear_rows += static_cast<std::uint64_t>(st.clip.y1 - st.clip.y0);
    stats.clear_pixels += std::uint64_t{cols} * static_cast<std::uint64_t>(st.clip.y1 - st.clip.y0);
    for (int y = st.clip.y0; y < st.clip.y1; ++y) {
      const std::uint64_t at = base + (std::uint64_t(y) * st.fb_width + st.clip.x0) * bpp;
      dropped |= !mem.write(at, row.data(), row.size());
      stats.clear_bytes += row.size();
      if (renderer.counts_sdram_rows()) renderer.sdram_rows().touch_range(at, row.size());
    }
    if (dropped) errors |= ERR_MEM_RANGE;
  }
  void clear_color() {
    const DrawState& st = draw_state();
    std::uint8_t px[4];
    store_pixel(st.fb_format, px, rgba_from_word(static_cast<std::uint32_t>(regs[index_of(Reg::CLEAR_COLOR)])));
    fill_rect(st.fb_draw, st.bpp, px);
  }
  void clear_depth() {
    const DrawState& st = draw_state();
    std::uint8_t px[4];
    store_be32(px, static_cast<std::uint32_t>(regs[index_of(Reg::CLEAR_DEPTH)] & 0xFFFFFF));
    fill_rect(st.fb_z, 4, px);
  }

  // --- swap and scanout ---
  void swap(std::uint64_t data) {
    renderer.flush();
    const DrawState& st = draw_state();
    ++stats.swaps;
    auto frame = scanout.latch(mem, static_cast<std::uint32_t>(data & 0xFFFFFFF0u), st.fb_width, st.fb_height,
                               st.fb_format, static_cast<bool>(scanout_cb), errors);
    if (scanout_cb && frame) scanout_cb(std::move(frame));
  }

  // --- memory access (section 2.4) ---
  std::uint64_t mem_addr() const { return regs[index_of(Reg::MEM_ADDR)] & 0xFFFFFFF8u; }
  void set_mem_addr(std::uint64_t a) { regs[index_of(Reg::MEM_ADDR)] = a & 0xFFFFFFF8u; }
  void load_prefetch() {
    renderer.flush();
    std::uint8_t b[8];
    // Bytes beyond VRAM read as 0; the error is raised when a MEM_DATA read returns them, so
    // writing the last word of memory does not flag the look-ahead.
    prefetch_beyond = !mem.read(mem_addr(), b, 8);
    prefetch = load_be64(b);
    mem_ready = true;
  }
  void write_mem_data(std::uint64_t data) {
    renderer.flush();
    ++stats.mem_data_writes;
    std::uint8_t b[8];
    store_be64(b, data);
    if (!mem.write(mem_addr(), b, 8)) errors |= ERR_MEM_RANGE;
    regs[index_of(Reg::MEM_DATA)] = data;
    set_mem_addr(mem_addr() + 8);
    load_prefetch();
  }

  // --- immediate writes ---
  void immediate(std::uint8_t index, std::uint64_t raw) {
    if (static_cast<Reg>(index) == Reg::RESET) {
      if (raw != kResetMagic) {
        validate(index, raw);
        errors |= ERR_BAD_VALUE;
        return;
      }
      soft_reset();
      return;
    }
    const std::uint64_t data = validate(index, raw);
    switch (static_cast<Reg>(index)) {
      case Reg::ERR_CLEAR: {
        const WriteCheck c = check_write(index, raw);
        errors = static_cast<std::uint16_t>(current_errors() & ~(data & 0xFFFF));
        errors |= c.errors;  // a malformed ERR_CLEAR still reports itself
        break;
      }
      case Reg::LINK_CTRL:
        // Leaving strict mode takes CLEAR_KEY (1.3): a frame garbled into LINK_CTRL by a bit
        // error must not switch the protection off. Refused: nothing changes (section 4).
        if (strict && !(data & 1) && (raw >> 32) != kLinkClearKey) {
          errors |= ERR_BAD_VALUE;
          break;
        }
        regs[index] = data & 1;  // CLEAR_KEY reads 0
        strict = data & 1;
        discard_held();
        discarding = false;
        restart_link_group();
        break;
      case Reg::LINK_CHECK: link_check(static_cast<std::uint32_t>(data)); break;
      case Reg::HOST_TAG: host_tag = data; break;
      default: break;
    }
  }

  void discard_held() {
    fifo.resize(fifo.size() - held);
    held = 0;
  }

  void link_check(std::uint32_t host_crc) {
    if (discarding) return;  // ignored until LINK_CTRL
    fold_crc();
    const bool match = host_crc == link_crc && !group_failed;
    if (match) {
      ++groups_ok;
      held = 0;  // release the group
      if (untimed()) run_released(fifo.size());
    } else {
      ++groups_bad;
      errors |= ERR_LINK_CRC;
      if (strict) {
        discard_held();
        discarding = true;
      }
    }
    restart_link_group();
  }

  void soft_reset() {
    renderer.flush();
    fifo.clear();
    held = 0;
    reset_registers();
    vertex_count = 0;
    errors = 0;
    renderer.take_errors();
    host_tag = 0;
    strict = discarding = false;
    groups_ok = groups_bad = 0;
    restart_link_group();
    prefetch = 0;
    mem_ready = false;
    scanout.reset();
  }

  // --- arrival of a complete frame ---
  // True when a queued write arriving now would execute at once: no group is held or being
  // discarded (not strict), the FIFO is empty and untimed. Only frames handled by frame() change
  // any of this: executing a queued write never does.
  bool executes_at_once() const { return !strict && !discarding && untimed() && fifo.empty(); }

  // Device::write(FrameView): the same effect as frame() on each frame in turn, with the frames
  // facts.vertex_write names taken straight from the wire while executes_at_once(). Their CRC and
  // counts are taken per run (take_run), before the next frame that goes through frame() and at
  // the end of the batch, so whatever looks at them (a LINK_CHECK, a read, a swap's scanout
  // callback, the caller after the batch) sees them as frame-by-frame arrival leaves them. Only a
  // pixel observer, called while a run's triangles are drawn, could see them lag; it gets pixels,
  // not the device.
  void write_frames(FrameView frames) {
    const std::uint8_t* b = frames.bytes.data();
    const std::uint8_t* const end = b + frames.size() * kFrameBytes;
    const std::uint8_t* run = b;  // first frame of the current run
    bool at_once = executes_at_once();
    for (; b != end; b += kFrameBytes) {
      if (at_once && facts.vertex_write[b[0]]) {
        execute_vertex_write(b[0], load_be64(b + 1));
        continue;
      }
      take_run(run, b);
      run = b + kFrameBytes;
      const Frame f{(b[0] & 0x80) != 0, static_cast<std::uint8_t>(b[0] & 0x7F), load_be64(b + 1)};
      if (f.read) read(f.index);
      frame(f);
      at_once = executes_at_once();
    }
    take_run(run, end);
  }

  void frame(const Frame& f) {
    ++stats.frames_received;
    const auto reg = static_cast<Reg>(f.index);
    if (reg != Reg::LINK_CHECK && reg != Reg::LINK_CTRL) feed_crc(f);
    if (!f.read) arrive_write(f.index, f.data);
    if (!untimed() && ++frame_tick % opt.fifo_drain_interval == 0) run_released(opt.fifo_drain_per_frame);
  }

  void arrive_write(std::uint8_t index, std::uint64_t data) {
    const RegisterDesc* d = facts.desc[index];
    if (!d || d->access == Access::ReadOnly) {
      errors |= ERR_BAD_REGISTER;
      return;
    }
    if (d->path == Path::Immediate) {
      immediate(index, data);
      return;
    }
    if (discarding) return;
    if (fifo.size() >= opt.fifo_depth) {
      errors |= ERR_OVERFLOW;
      group_failed = true;
      return;
    }
    if (!strict && untimed() && fifo.empty()) {  // nothing waits: execute at once
      execute(FifoEntry{index, data});
      return;
    }
    fifo.push_back(FifoEntry{index, data});
    if (strict) ++held;
    else if (untimed()) run_released(fifo.size());
  }

  // --- reads ---
  std::uint64_t read(std::uint8_t index) {
    const RegisterDesc* d = find_register(index);
    if (!d) {
      errors |= ERR_BAD_REGISTER;
      return 0;
    }
    if (d->access == Access::WriteOnly) return 0;
    switch (static_cast<Reg>(index)) {
      case Reg::STATUS: {
        renderer.flush();
        const std::uint64_t e = current_errors();
        return (e << 48) | (std::uint64_t{scanout.frame_count()} << 32) |
               (std::uint64_t{strict && held > 0} << 20) | (std::uint64_t{mem_ready} << 18) | (1ull << 17) |
               (std::uint64_t{!fifo.empty()} << 16) | fifo.size();
      }
      case Reg::FRAME_CRC: return scanout.frame_crc_register();
      case Reg::LINK_STATUS:
        return (std::uint64_t{groups_bad} << 48) | (std::uint64_t{groups_ok} << 32) |
               (std::uint64_t{discarding} << 24) | link_frames;
      case Reg::HOST_TAG: return host_tag;
      case Reg::CAPS: return caps;
      case Reg::CAPS2: return caps2;
      case Reg::ID: return id;
      case Reg::MEM_DATA: {
        const std::uint64_t v = prefetch;
        if (prefetch_beyond) errors |= ERR_MEM_RANGE;
        set_mem_addr(mem_addr() + 8);
        mem_ready = false;
        load_prefetch();  // completes before the next frame's bit 64 (section 2.4)
        return v;
      }
      default: return regs[index];
    }
  }

  std::uint8_t miso() {
    const std::uint16_t e = current_errors();
    std::uint8_t b = MISO_MARKER | MISO_VBLANK;
    if (opt.fifo_depth - fifo.size() < 32) b |= MISO_FIFO_NEARLY_FULL;
    if (e) b |= MISO_ERROR;
    if (!fifo.empty()) b |= MISO_BUSY;
    if (mem_ready) b |= MISO_MEM_READY;
    return b;
  }
};

Result<std::unique_ptr<Device>> Device::create(const DeviceOptions& options) {
  if (auto v = options.validate(); !v) return v.error();
  return std::unique_ptr<Device>(new Device(std::make_unique<State>(options)));
}

Device::Device(std::unique_ptr<State> state) : s_(std::move(state)) {}
Device::~Device() = default;

std::uint8_t Device::miso_status() { return s_->miso(); }
std::uint64_t Device::read_register(std::uint8_t index) { return s_->read(index & 0x7F); }
void Device::frame_complete(const protocol::Frame& frame) {
  Frame f = frame;
  f.index &= 0x7F;
  s_->frame(f);
}
void Device::frame_aborted() {
  ++s_->stats.frames_aborted;
  s_->errors |= ERR_FRAMING;
  s_->group_failed = true;
}
bool Device::busy_pin() const { return s_->opt.fifo_depth - s_->fifo.size() < 32; }

void Device::write(const protocol::Frame& frame) {
  if (frame.read) s_->read(frame.index & 0x7F);
  frame_complete(frame);
}
void Device::write(protocol::FrameView frames) { s_->write_frames(frames); }
std::uint64_t Device::read(std::uint8_t index) {
  const std::uint64_t v = s_->read(index & 0x7F);
  frame_complete(Frame{true, static_cast<std::uint8_t>(index & 0x7F), 0});
  return v;
}
void Device::drain() { s_->run_released(s_->fifo.size()); }
unsigned Device::step(unsigned n) {
  const std::size_t before = s_->fifo.size();
  s_->run_released(n);
  return static_cast<unsigned>(before - s_->fifo.size());
}

std::span<std::uint8_t> Device::memory() {
  s_->renderer.flush();
  return s_->mem.span();
}
std::span<const std::uint8_t> Device::memory() const {
  s_->renderer.flush();
  return s_->mem.span();
}
void Device::set_scanout_callback(backends::ScanoutCallback cb) { s_->scanout_cb = std::move(cb); }
void Device::set_pixel_observer(PixelObserver observer) {
  s_->renderer.flush();
  s_->renderer.set_observer(std::move(observer));
}
const DeviceOptions& Device::options() const { return s_->opt; }
std::uint64_t Device::caps() const { return s_->caps; }
std::uint64_t Device::caps2() const { return s_->caps2; }
std::uint64_t Device::id() const { return s_->id; }
std::uint16_t Device::errors() const {
  s_->renderer.flush();
  return s_->current_errors();
}
const DeviceStats& Device::stats() const {
  s_->renderer.flush();
  DeviceStats& st = s_->stats;
  const RasterCounters& c = s_->renderer.counters();
  st.triangles_rasterised = s_->renderer.triangles_rasterised();
  st.pixels_scanned = c.scanned;
  st.pixels_covered = c.covered;
  st.pixels_depth_passed = c.passed;
  st.pixels_textured = c.textured;
  st.pixels_blended = c.blended;
  st.texel_bytes = c.texel_bytes;
  st.by_mode = s_->renderer.mode_work();
  st.triangles_rejected = s_->renderer.triangles_rejected();
  st.texel_footprint_bytes = s_->renderer.texel_footprint();
  st.texel_fetches = s_->renderer.texel_cache().misses();
  st.sdram_accesses = s_->renderer.sdram_rows().hits() + s_->renderer.sdram_rows().opens() + s_->renderer.sdram_rows().misses();
  st.row_opens = s_->renderer.sdram_rows().opens();
  st.row_misses = s_->renderer.sdram_rows().misses();
  st.textured_row_misses = s_->renderer.sdram_rows().textured_misses();
  st.depth_tail_pixels = s_->renderer.depth_tail();
  return st;
}
void Device::reset_stats() {
  s_->renderer.flush();
  s_->stats = {};
  s_->renderer.reset_counters();
}

}  // namespace gpubridge::sim
