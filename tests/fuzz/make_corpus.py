#!/usr/bin/env python3
"""Writes the seed corpora of the fuzz targets (tests/fuzz/corpus/<target>/). The byte layouts
follow docs/protocol.md sections 17 and 18; rerun after a format change:
    python3 tests/fuzz/make_corpus.py [path/to/gpubridge]
The scene, config and board profile seeds are copies of the shipped examples/configs plus a few
hand-written ones; the PNG seeds are frames written by `gpubridge render` (the project's own PNG
writer, when the CLI path is given) plus a few colour types it never writes (grey, palette,
16-bit, interlaced) built here; the USB seeds are scripts for fuzz_usb_bridges.cpp that open each
chip and run one write and one read transfer successfully.
"""
import base64
import glob
import json
import os
import shutil
import struct
import subprocess
import sys
import tempfile
import zlib

HERE = os.path.dirname(os.path.abspath(__file__))


def msg(mtype, payload=b"", rid=1):
    return b"GB" + struct.pack("<BBII", 1, mtype, len(payload), rid) + payload


def frame(index, data, read=False):
    return bytes([(0x80 if read else 0) | index]) + struct.pack(">Q", data)


def hello(name=b"fuzz", token=b"", codecs=None):
    extra = b"" if codecs is None else bytes([codecs])
    return msg(0x01, struct.pack("<HB", 1, len(name)) + name + bytes([len(token)]) + token + extra)


def zstd(data):
    return subprocess.run(["zstd", "-q", "-1", "-c"], input=data, capture_output=True, check=True).stdout


def write_frames_z(frames, rid):
    """WRITE_FRAMES_Z (docs/protocol.md 17.6): codec 1 (zstd), frames_bytes, compressed frames."""
    return msg(0x17, struct.pack("<BI", 1, len(frames)) + zstd(frames), rid)


FRAMES = frame(0x0F, (480 << 16) | 640) + frame(0x0B, 0) + frame(0x02, 0x00FFFFFF00100020) + frame(0x04, 0x0D)

MESSAGES = {
    "hello": hello(b"viewer", b"secret"),
    "handshake_session": hello() + msg(0x40, b"\x00") + msg(0x10, FRAMES, 2) + msg(0x20, struct.pack("<Q", 7), 3)
    + msg(0x06),
    "welcome": msg(0x02, struct.pack("<HII", 1, 1 << 20, 5) + b'{"backend":"sim","caps":[1,2]}'),
    "error": msg(0x03, struct.pack("<HI", 9, 2) + b"no lease"),
    "ping_pong": msg(0x04, b"abc") + msg(0x05, b"abc"),
    "upload_readback": msg(0x13, struct.pack("<I", 0x1000) + bytes(range(32))) + msg(0x15, struct.pack("<II", 0, 64))
    + msg(0x16, struct.pack("<IB", 0, 1) + b"\x01\x02"),
    "regs": msg(0x11, b"\x10") + msg(0x12, b"\x7f" + struct.pack("<Q", 0x5350475501000000)),
    "status": msg(0x22) + msg(0x23, b'{"fifo":0,"busy":false}'),
    "subscribe_frame": msg(0x30, struct.pack("<BH", 2, 30))
    + msg(0x32, struct.pack("<IHHBBIQ", 1, 2, 2, 1, 0, 0xDEADBEEF, 1000) + bytes(8)) + msg(0x31),
    "lease": msg(0x40, b"\x01") + msg(0x41, struct.pack("<I", 3)) + msg(0x42) + msg(0x43),
    "event": msg(0x50, b'{"event":"unplugged"}'),
    "bad_read_bit": msg(0x10, frame(0x10, 0, read=True)),
    "huge_length": b"GB\x01\x13" + struct.pack("<II", 0xFFFFFFFF, 1),
    # HELLO offering zstd, then a compressed batch, a zip bomb (1 MiB declared as 9 bytes) and a
    # compressed read frame.
    "zstd_session": hello(codecs=1) + msg(0x40, b"\x00") + write_frames_z(FRAMES * 8, 2)
    + msg(0x20, struct.pack("<Q", 7), 3),
    "zstd_bomb": hello(codecs=1) + msg(0x40, b"\x00")
    + msg(0x17, struct.pack("<BI", 1, 9) + zstd(bytes(1 << 20)), 2),
    "zstd_read_frame": hello(codecs=1) + msg(0x40, b"\x00") + write_frames_z(frame(0x10, 0, read=True), 2),
}

# DMC1_WORDS (docs/protocol.md 17.7): two command words (a wall span and an end of column), and two
# malformed ones (empty, not whole words).
DMC1_WORDS = struct.pack("<QQ", 0x0000FFFF3FBC0000, 0xC0000001)
MESSAGES["dmc1_words"] = msg(0x18, DMC1_WORDS)
MESSAGES["dmc1_words_empty"] = msg(0x18, b"")
MESSAGES["dmc1_words_partial"] = msg(0x18, DMC1_WORDS[:12])
# After daemon_session_fuzz's own HELLO: a lease, DMC-1 words (the fuzzer's spigpu backend answers
# WRONG_DEVICE), then a fence.
SESSION_DMC1 = {
    "session_dmc1_words": msg(0x40, b"\x00") + msg(0x18, DMC1_WORDS * 4, 2) + msg(0x20, struct.pack("<Q", 7), 3),
}

# After daemon_session_fuzz's own HELLO (offering zstd): a lease, then a compressed batch and a
# fence, a zip bomb, or a compressed read frame.
SESSION_ZSTD = {
    "session_zstd_batch": msg(0x40, b"\x00") + write_frames_z(FRAMES * 8, 2) + msg(0x20, struct.pack("<Q", 7), 3),
    "session_zstd_bomb": msg(0x40, b"\x00") + msg(0x17, struct.pack("<BI", 1, 9) + zstd(bytes(1 << 20)), 2),
    "session_zstd_read_frame": msg(0x40, b"\x00") + write_frames_z(frame(0x10, 0, read=True), 2),
}


def trace(records, meta=b'{"created_by":"make_corpus.py"}'):
    out = b"GBTRACE\x00" + struct.pack("<HHI", 1, 0, len(meta)) + meta
    for ts, m in records:
        out += struct.pack("<Q", ts) + m
    return out


TRACES = {
    "empty": trace([]),
    "session": trace([(0, msg(0x10, FRAMES, 1)), (10, msg(0x13, struct.pack("<I", 0x100) + b"\xde\xad", 2)),
                      (20, msg(0x20, struct.pack("<Q", 1), 3)), (30, msg(0x11, b"\x10", 4)),
                      (40, msg(0x15, struct.pack("<II", 0, 16), 5))]),
    "two_batches": trace([(0, msg(0x10, frame(0x0B, 0))), (0, msg(0x10, frame(0x42, 0x1234)))]),
    "nested_meta": trace([], json.dumps({"device": {"backend": "sim", "size": [640, 480]}}).encode()),
    # A recorded DMC-1 session (gpubridged --record on --backend dmc1), and a device kind nobody knows.
    "dmc1_session": trace([(0, msg(0x18, DMC1_WORDS, 1)), (5, msg(0x20, struct.pack("<Q", 1), 2)),
                           (9, msg(0x18, DMC1_WORDS * 3, 3))], b'{"source":"gpubridged","device_kind":"dmc1"}'),
    "unknown_kind": trace([], b'{"device_kind":"vga"}'),
}

TEXTS = {
    "triangle.trace": """# a shaded triangle
.meta {"created_by": "hand"}
FB_FORMAT FORMAT=RGB565 WIDTH=320 HEIGHT=240
CLEAR_COLOR R=16 G=16 B=48 A=255
CLEAR
TRI_MODE GOURAUD=1 Z_TEST=1 Z_FUNC=LEQUAL BLEND=ALPHA
PRIM TYPE=STRIP
COLOR Q=0.5 R=255 A=255
TEXCOORD S=-1.25 T=0.0625
VERTEX X=40 Y=200.5 Z=0x100
VERTEX X=160 Y=20
VERTEX X=280.25 Y=200.5
.fence 1
""",
    "directives.trace": """.upload 0x1000 png tex.png RGB565
.upload 0x2000 hex data.hex
.mem 0x100 deadbeef 0x00
.batch
0x42 0xDEAD
.read STATUS
.read 0x55
.readback 0 64
HOST_TAG 0xFFFF_FFFF_FFFF_FFFF
TEX_BASE 4096
""",
    "errors.trace": "VERTEX X=100.3\nSTATUS 1\nTRI_MODE Z_FUNC=NOPE\n.upload 0 png x.png\n",
    "all_regs.trace": "".join(
        f"{name}\n" for name in ["COLOR", "TEXCOORD", "VERTEX", "PRIM", "TRI_MODE", "TEX_BASE", "TEX_FMT", "SCISSOR",
                                 "FB_DRAW", "FB_DISPLAY", "CLEAR_COLOR", "CLEAR", "CLEAR_Z", "CLEAR_DEPTH", "FB_Z",
                                 "FB_FORMAT", "ERR_CLEAR", "LINK_CTRL", "LINK_CHECK", "HOST_TAG", "RESET", "FENCE",
                                 "MEM_ADDR", "MEM_DATA"]),
    # Metadata naming a kind a text trace cannot hold; both were accepted and then made binary traces
    # every reader refused (stop 41's CI).
    "meta-device-kind-dmc1": '.meta {"device_kind":"dmc1"}\n',
    "meta-device-kind-number": '.meta {"device_kind":5}\n',
}


def write(target, name, data):
    d = os.path.join(HERE, "corpus", target)
    os.makedirs(d, exist_ok=True)
    with open(os.path.join(d, name), "wb") as f:
        f.write(data if isinstance(data, bytes) else data.encode())


ROOT = os.path.dirname(os.path.dirname(HERE))

EXTRA_SCENES = {
    "arrays_state.json": {
        "framebuffer": {"width": 32, "height": 24, "format": "RGB565", "depth": True},
        "clear": {"color": [0, 0, 0, 1], "depth": 1},
        "draws": [
            {"z_test": True, "z_write": True, "z_func": "LEQUAL", "cull": "back", "scissor": [1, 1, 30, 20],
             "blend": "ADD", "dither": True, "write_mask": "rgb", "gouraud": False, "color": [0.5, 0.5, 0.5],
             "vertices": [[0, 0, 0.5, 1], [31, 0, 0.5, 2, 1, 0, 0, 1], [0, 23, 0.25, 0.5, 0, 1, 0, 1, 0, 1]]},
        ],
    },
}


def png_chunk(kind, data):
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)


def png(width, height, depth, color_type, rows, interlace=0, extra=b""):
    """A PNG from already-packed rows (filter byte 0 is added here; interlaced data is passed whole)."""
    ihdr = struct.pack(">IIBBBBB", width, height, depth, color_type, 0, 0, interlace)
    raw = rows if interlace else b"".join(b"\x00" + r for r in rows)
    return (b"\x89PNG\r\n\x1a\n" + png_chunk(b"IHDR", ihdr) + extra + png_chunk(b"IDAT", zlib.compress(raw))
            + png_chunk(b"IEND", b""))


def adam7_gray8(width, height):
    """Interlaced 8-bit grey: the seven Adam7 passes, each with filter bytes."""
    passes = [(0, 0, 8, 8), (4, 0, 8, 8), (0, 4, 4, 8), (2, 0, 4, 4), (0, 2, 2, 4), (1, 0, 2, 2), (0, 1, 1, 2)]
    out = b""
    for x0, y0, dx, dy in passes:
        xs = range(x0, width, dx)
        for y in range(y0, height, dy):
            if len(xs):
                out += b"\x00" + bytes((x * 16 + y * 8) & 0xFF for x in xs)
    return out


def synth(width, height, depth, color_type, interlace, palette, trns, raw):
    return struct.pack(">HHBBBBB", width, height, depth, color_type, interlace, len(palette) // 3, len(trns)) \
        + palette + trns + raw


SYNTH_PNGS = {
    "synth_rgb8_4x4": synth(4, 4, 8, 2, 0, b"", b"", b"".join(bytes([f]) + bytes(range(12)) for f in range(4))),
    "synth_palette4_interlaced": synth(5, 3, 4, 3, 1, bytes(range(48)), b"\x00\x80", bytes(range(40))),
    "synth_gray16_alpha": synth(2, 2, 16, 4, 0, b"", b"", bytes(range(2 * 9))),
}


def handmade_pngs():
    return {
        "gray1.png": png(8, 2, 1, 0, [b"\xa5", b"\x5a"]),
        "palette_trns.png": png(4, 2, 2, 3, [b"\x1b", b"\xe4"],
                                extra=png_chunk(b"PLTE", bytes([255, 0, 0, 0, 255, 0, 0, 0, 255, 9, 9, 9]))
                                + png_chunk(b"tRNS", b"\xff\x80\x00")),
        "rgb16.png": png(2, 2, 16, 2, [bytes(range(12)), bytes(range(12, 24))]),
        "gray_alpha8.png": png(3, 1, 8, 4, [b"\x10\xff\x80\x40\xf0\x00"]),
        "interlaced_gray8.png": png(9, 9, 8, 0, adam7_gray8(9, 9), interlace=1),
    }


def rendered_pngs(gpubridge):
    """8x8 and 16x8 frames written by the project's own PNG writer (gpubridge render)."""
    scenes = {
        "render_8x8.png": {"framebuffer": {"width": 8, "height": 8}, "clear": {"color": [0.2, 0.4, 0.6]},
                           "draws": [{"vertices": [[0, 0, 0, 1, 1, 0, 0], [8, 0, 0, 1, 0, 1, 0], [0, 8, 0, 1, 0, 0, 1]]}]},
        "render_16x8_alpha.png": {"framebuffer": {"width": 16, "height": 8, "format": "RGBA2222"},
                                  "clear": {"color": [1, 1, 1, 0.25]},
                                  "draws": [{"blend": "ALPHA", "color": [1, 0, 0, 0.5], "vertices": [[2, 1], [15, 4], [3, 7]]}]},
    }
    out = {}
    with tempfile.TemporaryDirectory() as tmp:
        for name, scene in scenes.items():
            src, dst = os.path.join(tmp, name + ".json"), os.path.join(tmp, name)
            with open(src, "w") as f:
                json.dump(scene, f)
            subprocess.run([gpubridge, "render", src, "--out", dst], check=True, stdout=subprocess.DEVNULL)
            with open(dst, "rb") as f:
                out[name] = f.read()
    return out


def usb_script(chip, cs, clock_khz, body):
    """fuzz_usb_bridges input: chip, options (0: FT232H, channel A, no BUSY), cs, packet size choice
    (0: 512 bytes), clock in kHz, then the script. OK = a successful OUT or setup call; IN(data) =
    a successful IN transfer of those bytes."""
    return bytes([chip, 0, cs, 0]) + struct.pack("<H", clock_khz) + body


OK = b"\x00"


def IN(data):
    return b"\x00" + bytes([len(data)]) + data


def window(size, capture):
    return struct.pack("<H", size) + bytes([1 if capture else 0, 0])


def usb_seeds():
    miso18 = bytes(range(18))
    ftdi_open = OK * 2 + OK * 8 + OK * 2 + IN(b"\x32\x60") + OK * 3 + IN(b"\x32\x60\xfa\xab")
    ftdi = ftdi_open + b"\x00" + window(100, False) + OK + b"\x00" + window(18, True) + OK + IN(b"\x32\x60" + miso18)
    ch341a = (OK * 4 + b"\x00" + window(40, True) + OK + IN(bytes(range(40))) + OK + b"\x00" + window(10, False) + OK
              + IN(bytes(10)) + OK)
    reply = lambda *b: IN(bytes(b) + bytes(64 - len(b)))
    mcp2210 = (OK + reply(0x11) + OK + reply(0x21, 0) + b"\x00" + window(9, True) + OK + reply(0x40, 0)
               + OK + reply(0x42, 0, 9, 0x10, *range(9)))
    cp2130 = OK * 4 + b"\x00" + window(9, True) + OK + IN(bytes(range(9))) + b"\x00" + window(64, False) + OK
    return {
        "ftdi_write_read": usb_script(0, 3, 30000, ftdi),
        "ch341a_read_write": usb_script(1, 0, 1500, ch341a),
        "mcp2210_read": usb_script(2, 0, 12000, mcp2210),
        "cp2130_read_write": usb_script(3, 0, 12000, cp2130),
    }


def copy_files(target, pattern):
    d = os.path.join(HERE, "corpus", target)
    os.makedirs(d, exist_ok=True)
    for f in sorted(glob.glob(os.path.join(ROOT, pattern))):
        shutil.copyfile(f, os.path.join(d, os.path.basename(f)))


def dmc1_seeds():
    """Stream-file seeds (dmc1_stream) and UART byte seeds (dmc1_link) from the golden streams."""
    stream = {}
    words = []
    with open(os.path.join(ROOT, "tests/dmc1/data/streams/edge.dmc1")) as f:
        lines = f.read().splitlines()
    stream["edge_head.dmc1"] = "\n".join(lines[:120]) + "\n"
    for line in lines:
        line = line.split("#")[0].strip()
        if line:
            words.append(int(line, 16))
    nfo = "".join("0," + "".join("0x%02x," % ((w >> (8 * b)) & 255) for b in range(7, -1, -1)) + "\n" for w in words[:80])
    stream["edge_head.nfo"] = nfo
    stream["bases.nfo"] = "7, 0b1, 0o17, 255, 0, 0XC0, 0, 0, 1\n0,0,0,0,0,0xc0,0,0,1,\n"
    stream["bad.dmc1"] = "00000000c0000001\nnot a word\n"
    link = {}
    framed = b"\x00\xaa" + b"".join(w.to_bytes(8, "big") for w in words[:100])
    link["edge_head.bin"] = b"\x17" + framed  # first byte: the wire model's baud selector
    lcd = b"".join(bytes(8) + w.to_bytes(8, "big") for w in (1 << 32 | 1 << 33, 1 << 32, 0x11, 0x3A, 0x155, 0x29))
    link["screen_init.bin"] = b"\x00\x12\x00\xaa" + (0x400).to_bytes(8, "big") + lcd
    return stream, link


def main():
    copy_files("scene", "examples/scenes/*.json")
    stream, link = dmc1_seeds()
    for name, data in stream.items():
        write("dmc1_stream", name, data)
    for name, data in link.items():
        write("dmc1_link", name, data)
    pngs = handmade_pngs()
    if len(sys.argv) > 1:
        pngs.update(rendered_pngs(sys.argv[1]))
        inline = dict(EXTRA_SCENES["arrays_state.json"])
        # An inline PNG texture: the 8x8 rendered frame, base64 in the scene.
        inline["textures"] = [{"name": "frame", "png_base64": base64.b64encode(pngs["render_8x8.png"]).decode(),
                               "format": "RGBA2222", "wrap_s": "CLAMP", "wrap_t": "MIRROR", "filter": "bilinear"}]
        inline["draws"] = [dict(inline["draws"][0], texture="frame", texture_mode="decal")]
        write("scene", "inline_png_texture.json", json.dumps(inline, indent=1))
    # fuzz_png.cpp: the first byte picks the mode (1: chunk CRCs repaired, 2: PNG built from fields).
    for name, data in pngs.items():
        write("png", name, b"\x01" + data)
    for name, data in SYNTH_PNGS.items():
        write("png", name, b"\x02" + data)
    for name, scene in EXTRA_SCENES.items():
        write("scene", name, json.dumps(scene, indent=1))
    copy_files("daemon_config", "configs/*.json")
    write("daemon_config", "comments.json", '// a comment\n{"listen": ["tcp:127.0.0.1:7000", "unix:/tmp/x.sock"], '
          '"token": "s3cret", /* inline */ "backend": "emulated:ft232h-generic", "limits": {"max_clients": 1}}\n')
    copy_files("board_profile", "configs/boards/*.json")
    for name, data in usb_seeds().items():
        write("usb_bridges", name, data)
    for name, data in MESSAGES.items():
        # The fuzz target's first byte chooses the receive limit (odd: small limit); keep it even here
        # so the seeds parse with the full limit.
        write("message_parser", name, b"\x00" + data)
    # daemon_session_fuzz shares this corpus but reads byte 0 as flags (bit 0: prepend a HELLO, bit 1:
    # that HELLO offers zstd, bits 2-4: read split count - 1) and the next bytes as split sizes:
    # 0x03 + one split byte reaches WRITE_FRAMES_Z inflation after a HELLO offering zstd.
    for name, data in SESSION_ZSTD.items():
        write("message_parser", name, b"\x03\x60" + data)
    for name, data in SESSION_DMC1.items():
        write("message_parser", name, b"\x01\x60" + data)
    for name, data in TRACES.items():
        write("binary_trace", name + ".gbt", data)
    for name, data in TEXTS.items():
        write("text_trace", name, data)


if __name__ == "__main__":
    main()
