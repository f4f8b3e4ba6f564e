// Colour stage (docs/protocol.md section 11 steps 4-6): destination read when blending or
// merging a write mask into a packed pixel, blend, quantise with the ordered dither, pack, write
// mask, and one word write with byte enables. Pixel i of the colour buffer is at byte
// FB_DRAW + i * bpp (big-endian pixels; byte 4k of a word is wdata[31:24], enable be[3]).
module core_color #(
    parameter integer AW = 2,            // log2 of destination reads in flight
    parameter integer IDX_W = 20,
    parameter integer ADDR_W = 32,
    parameter [7:0]   FEATURES = 8'hFF,  // CAPS.FEATURES: blend, dither, RGB565, RGBA2222 logic
    parameter integer PIPE = 0           // 1 (ecp5): three registered steps between the queue
                                         // head and the write register (below)
) (
    input  wire        clk,
    input  wire        rst,
    input  wire [1:0]  fmt,        // 0 RGBA8888, 1 RGB565, 2 RGBA2222
    input  wire [27:0] fb_draw16,
    input  wire [1:0]  blend,      // 0 OFF, 1 ALPHA, 2 ADD, 3 MULTIPLY
    input  wire        dither,
    input  wire        temporal,   // TRI_MODE.TEMPORAL (with DITHER)
    input  wire [3:0]  phase,      // TRI_MODE.DITHER_PHASE
    input  wire [3:0]  keep,       // 1 = keep the stored channel: bit 0 R .. bit 3 A
    input  wire        need_dst,   // read the destination (blend, or mask on a packed format)
    // pixels in: {yl[1:0], xl[1:0], idx, rgba[31:0]}
    input  wire        in_valid,
    output wire        in_ready,
    input  wire [IDX_W+35:0] in_pix,
    // memory
    output wire        rd_valid,
    input  wire        rd_ready,
    output wire [29:0] rd_addr,
    input  wire        rsp_valid,
    input  wire [31:0] rsp_data,
    output reg         wr_valid,
    input  wire        wr_ready,
    output reg  [29:0] wr_addr,
    output reg  [31:0] wr_data,
    output reg  [3:0]  wr_be,
    output wire        idle
);
  localparam F_BLEND = 1, F_DITHER = 2, F_RGB565 = 4, F_RGBA2222 = 5, F_TEMPORAL = 6;
  // Without blending and with one read in flight (up5k), a destination read only merges the
  // masked channels of a packed pixel: the pixel is quantised and packed before it waits, so the
  // queue holds its 16 packed bits (not its RGBA and screen position), and the response only the
  // half word of its lane.
  localparam integer PACKQ = (!FEATURES[F_BLEND] && AW == 0) ? 1 : 0;
  localparam integer QIW = (PACKQ != 0) ? 48 : 68;  // queue item bits
  localparam integer QDW = (PACKQ != 0) ? 16 : 32;  // response bits kept

`include "core_addr.vh"
  // {word, lane} of pixel idx: FB_DRAW + idx * bpp
  wire [IDX_W-1:0] in_idx = in_pix[IDX_W+31:32];
  wire [23:0] in_off = (fmt == 2'd0) ? {{(22-IDX_W){1'b0}}, in_idx, 2'b0} :
                       (fmt == 2'd1) ? {{(23-IDX_W){1'b0}}, in_idx, 1'b0} : {{(24-IDX_W){1'b0}}, in_idx};
  wire [31:0] in_addr_full = byte_addr(fb_draw16, in_off);
  // PACKQ (up5k): the lane is the offset's own low bits (FB_DRAW is 16-byte aligned, so the sum's low
  // bits are the offset's), not the sum's: byte_addr makes it all ones only where the address is beyond
  // VRAM, where the arbiter drops the write and answers a read with 0, so the lane chooses nothing
  // anyone sees there. It then no longer waits for the address's carry chain and range test, which
  // lay in front of the write data and byte enables (docs/gateware.md up5k-cells)
  wire [31:0] in_addr = (PACKQ != 0) ? {in_addr_full[31:2], in_off[1:0]} : in_addr_full;
  // the item from here on: {yl, xl, word address and lane, rgba}
  wire [67:0] in_item = {in_pix[IDX_W+35:IDX_W+32], in_addr, in_pix[31:0]};

  // ---- destination read queue ----
  // PACKQ: RGBA8888 has nothing to merge (a read would only feed a blend)
  wire        need_rd = (PACKQ != 0) ? (need_dst && fmt != 2'd0) : need_dst;
  wire        q_full, q_empty, q_head;
  wire [QIW-1:0] q_item, push_item;
  wire [QDW-1:0] q_data, rsp_kept;
  wire        take;
  wire [15:0] pk_n;     // PACKQ: the input pixel quantised and packed (below)
  wire [67:0] cur;      // the pixel quantised here: the queue head, or (PACKQ) the input
  generate
    if (PACKQ != 0) begin : packed_item
      assign push_item = {in_addr, pk_n};
      // one read in flight: the response is the single slot's, whose lane picks the half word
      assign rsp_kept = q_item[17] ? rsp_data[15:0] : rsp_data[31:16];
      assign cur = in_item;
    end else begin : full_item
      assign push_item = in_item;
      assign rsp_kept = rsp_data;
      assign cur = need_rd ? q_item : in_item;
      wire unused_pk = &{1'b0, pk_n};
    end
  endgenerate
  core_rdq #(.IW(QIW), .DW(QDW), .AW(AW)) queue (
      .clk(clk), .rst(rst),
      .push(rd_valid && rd_ready), .push_item(push_item),
      .full(q_full), .empty(q_empty),
      .rsp_valid(rsp_valid), .rsp_data(rsp_kept),
      .head_valid(q_head), .head_item(q_item), .head_data(q_data), .pop(need_rd && take));
  assign rd_valid = need_rd && in_valid && !q_full;
  assign rd_addr  = in_addr[31:2];

  // the pixel being written: its address and (PACKQ) its packed value
  wire        cur_valid = need_rd ? q_head : in_valid;
  wire [31:0] dword = 32'(q_data);
  wire [31:0] addr = (PACKQ != 0) ? (need_rd ? q_item[QIW-1:QIW-32] : in_addr) : wcur[63:32];
  wire [15:0] pk = need_rd ? q_item[15:0] : pk_n;
  wire [1:0]  lane = addr[1:0];
  wire [1:0]  xl, yl;

  // ---- PIPE: the pixel, its destination word and its blend over three registered steps ----
  // (the ULX3S clock, docs/gateware.md "Clock estimate"): p1 the queue head (or input) and its
  // word, p2 the blend before its division by 255 (the products), p3 the blended channels; the
  // write register quantises, packs and masks p3. One enable (the write register free) moves
  // them all, so a pixel a clock still leaves. PIPE = 0: every step is the pixel of this clock.
  localparam integer PP = (PIPE != 0 && PACKQ == 0) ? 1 : 0;
  wire        pen = !wr_valid || wr_ready;
  reg         p1v, p2v, p3v;
  reg [67:0]  p1c, p2c, p3c;
  reg [31:0]  p1d, p2d, p3d;
  reg [31:0]  p1x;                               // p1's destination, 8 bits a channel
  wire [67:0] bcur = (PP != 0) ? p1c : cur;      // the pixel blended
  wire [67:0] wcur = (PP != 0) ? p3c : cur;      // the pixel written
  wire [31:0] wdword = (PP != 0) ? p3d : dword;

  // ---- destination pixel, expanded to 8 bits per channel ----
  function [15:0] dst16(input [31:0] w, input ln1);  // ln1: lane bit 1
    dst16 = (PACKQ != 0 || ln1) ? w[15:0] : w[31:16];
  endfunction
  function [7:0] dst8(input [31:0] w, input [1:0] ln);
    reg [15:0] h;
    begin
      h = dst16(w, ln[1]);
      dst8 = (PACKQ != 0) ? (ln[0] ? h[7:0] : h[15:8]) :
             (ln == 2'd0) ? w[31:24] : (ln == 2'd1) ? w[23:16] : (ln == 2'd2) ? w[15:8] : w[7:0];
    end
  endfunction
  assign xl = wcur[65:64];
  assign yl = wcur[67:66];
  wire [15:0] d16 = dst16(wdword, lane[1]);
  wire [7:0]  d8 = dst8(wdword, lane);
  function [31:0] expand(input [1:0] f, input [15:0] h, input [7:0] b, input [31:0] w);
    case (f)
      2'd1: expand = {h[15:11], h[15:13], h[10:5], h[10:9], h[4:0], h[4:2], 8'hFF};
      2'd2: expand = {{4{b[7:6]}}, {4{b[5:4]}}, {4{b[3:2]}}, {4{b[1:0]}}};
      default: expand = w;
    endcase
  endfunction
  // PP: expanded before p1 (its lane from the pixel entering p1), so p1 holds it ready for the blend
  wire [31:0] dexp = (PP != 0) ? p1x : expand(fmt, d16, d8, dword);
  wire [7:0]  dr = dexp[31:24], dg = dexp[23:16], db = dexp[15:8], da = dexp[7:0];
  wire [31:0] dexp_in = expand(fmt, dst16(dword, cur[33]), dst8(dword, cur[33:32]), dword);
  wire unused_pp = &{1'b0, bcur[67:32], wcur[31:0], dexp_in};  // blended: the colour; written: the rest

  // ---- blend ----
  function [7:0] div255(input [16:0] x);
    reg [16:0] y;
    begin
      y = x + 17'd128;
      div255 = 8'((y + {8'd0, y[16:8]}) >> 8);
    end
  endfunction
  wire [7:0] sa = bcur[7:0];
  // the blend before its division by 255 (ALPHA, MULTIPLY), or its result (OFF, ADD)
  function [16:0] blend_pre(input [1:0] m, input [7:0] s, input [7:0] d, input [7:0] a);
    case (m)
      // ALPHA: s*a + d*(255-a) = d*255 + a*(s-d), in [0, 65025]
      2'd1: blend_pre = 17'($signed({1'b0, d, 8'd0}) - $signed({10'd0, d}) +
                            $signed({10'd0, a}) * ($signed({10'd0, s}) - $signed({10'd0, d})));
      2'd2: blend_pre = {9'd0, ({1'b0, s} + {1'b0, d} > 9'd255) ? 8'hFF : s + d};  // ADD
      2'd3: blend_pre = {1'b0, 16'(s) * 16'(d)};                                  // MULTIPLY
      default: blend_pre = {9'd0, s};
    endcase
  endfunction
  function [7:0] blend_post(input [1:0] m, input [16:0] x);
    blend_post = (m == 2'd1 || m == 2'd3) ? div255(x) : x[7:0];
  endfunction
  wire [1:0] bm = FEATURES[F_BLEND] ? blend : 2'd0;
  wire [16:0] xr = blend_pre(bm, bcur[31:24], dr, sa);
  wire [16:0] xg = blend_pre(bm, bcur[23:16], dg, sa);
  wire [16:0] xb = blend_pre(bm, bcur[15:8], db, sa);
  wire [16:0] xa = blend_pre(bm, bcur[7:0], da, sa);
  reg  [16:0] p2r, p2g, p2b, p2a;
  reg  [7:0]  p3r, p3g, p3b, p3a;
  wire [7:0] cr = (PP != 0) ? p3r : blend_post(bm, xr);
  wire [7:0] cg = (PP != 0) ? p3g : blend_post(bm, xg);
  wire [7:0] cb = (PP != 0) ? p3b : blend_post(bm, xb);
  wire [7:0] ca = (PP != 0) ? p3a : blend_post(bm, xa);
  always @(posedge clk) begin
    if (rst || PP == 0) begin
      p1v <= 1'b0; p2v <= 1'b0; p3v <= 1'b0;
    end else if (pen) begin
      p1v <= cur_valid; p2v <= p1v; p3v <= p2v;
    end
    if (pen) begin
      p1c <= cur; p1d <= dword; p1x <= dexp_in;
      p2c <= p1c; p2d <= p1d;
      p2r <= xr; p2g <= xg; p2b <= xb; p2a <= xa;
      p3c <= p2c; p3d <= p2d;
      p3r <= blend_post(bm, p2r); p3g <= blend_post(bm, p2g);
      p3b <= blend_post(bm, p2b); p3a <= blend_post(bm, p2a);
    end
  end

  // ---- quantise and dither (4x4 Bayer at screen position) ----
  reg [3:0] bayer;
  always @(*) begin
    case ({yl, xl})
      4'h0: bayer = 4'd0;  4'h1: bayer = 4'd8;  4'h2: bayer = 4'd2;  4'h3: bayer = 4'd10;
      4'h4: bayer = 4'd12; 4'h5: bayer = 4'd4;  4'h6: bayer = 4'd14; 4'h7: bayer = 4'd6;
      4'h8: bayer = 4'd3;  4'h9: bayer = 4'd11; 4'hA: bayer = 4'd1;  4'hB: bayer = 4'd9;
      4'hC: bayer = 4'd15; 4'hD: bayer = 4'd7;  4'hE: bayer = 4'd13; default: bayer = 4'd5;
    endcase
  end
  wire dith = FEATURES[F_DITHER] && dither;
  // temporal dither (protocol 1.1, CAPS bit 6): threshold t = B ^ reverse4(DITHER_PHASE), the
  // channel scaled to 0..2^n-1 with a centred threshold
  wire tdith = FEATURES[F_TEMPORAL] && dith && temporal;
  wire [3:0] thr = bayer ^ (tdith ? {phase[0], phase[1], phase[2], phase[3]} : 4'd0);
  // ordered: min(255, v + ((t << (8 - n)) >> 4)) >> (8 - n); without dither: v >> (8 - n)
  function [7:0] sat8(input [8:0] x);
    sat8 = x[8] ? 8'hFF : x[7:0];
  endfunction
  // temporal: a = (v << n) - v; (a + (a >> 8) + 16 t + 8) >> 8, never above 2^n - 1
  function [5:0] temporal_q(input [7:0] v, input [2:0] n, input [3:0] t);
    reg [13:0] a;
    begin
      a = ({6'd0, v} << n) - {6'd0, v};
      temporal_q = 6'((a + (a >> 8) + {6'd0, t, 4'd8}) >> 8);
    end
  endfunction
  wire [3:0] t5 = dith ? {1'b0, thr[3:1]} : 4'd0;  // (t << 3) >> 4
  wire [3:0] t6 = dith ? {2'b0, thr[3:2]} : 4'd0;  // (t << 2) >> 4
  wire [7:0] t2 = dith ? {2'd0, thr, 2'd0} : 8'd0; // (t << 6) >> 4
  // PACKQ (up5k, no temporal dither): one saturating add per channel for both packed formats,
  // its threshold scaled by the format (RGBA2222: t2, RGB565: t5 or t6), instead of an adder
  // per channel and format (fit9, docs/gateware.md: 16 carry cells)
  wire       f2 = (fmt == 2'd2);
  wire [7:0] sq_r = sat8({1'b0, cr} + {1'b0, f2 ? t2 : {4'd0, t5}});
  wire [7:0] sq_g = sat8({1'b0, cg} + {1'b0, f2 ? t2 : {4'd0, t6}});
  wire [7:0] sq_b = sat8({1'b0, cb} + {1'b0, f2 ? t2 : {4'd0, t5}});
  wire [7:0] sq_a = sat8({1'b0, ca} + {1'b0, t2});
  wire [4:0] r5q = tdith ? 5'(temporal_q(cr, 3'd5, thr)) : (PACKQ != 0) ? sq_r[7:3] : 5'(sat8({1'b0, cr} + {5'd0, t5}) >> 3);
  wire [5:0] g6q = tdith ? temporal_q(cg, 3'd6, thr) : (PACKQ != 0) ? sq_g[7:2] : 6'(sat8({1'b0, cg} + {5'd0, t6}) >> 2);
  wire [4:0] b5q = tdith ? 5'(temporal_q(cb, 3'd5, thr)) : (PACKQ != 0) ? sq_b[7:3] : 5'(sat8({1'b0, cb} + {5'd0, t5}) >> 3);
  function [1:0] q2(input [7:0] v, input [7:0] add, input [1:0] s, input td, input [3:0] t);
    q2 = td ? 2'(temporal_q(v, 3'd2, t)) : (PACKQ != 0) ? s : 2'(sat8({1'b0, v} + {1'b0, add}) >> 6);
  endfunction
  wire [1:0] r2q = q2(cr, t2, sq_r[7:6], tdith, thr), g2q = q2(cg, t2, sq_g[7:6], tdith, thr);
  wire [1:0] b2q = q2(cb, t2, sq_b[7:6], tdith, thr), a2q = q2(ca, t2, sq_a[7:6], tdith, thr);
  wire unused_sq = &{1'b0, sq_r[2:0], sq_g[1:0], sq_b[2:0], sq_a[5:0]};

  // ---- pack, write mask ----
  assign pk_n = (fmt == 2'd1) ? {r5q, g6q, b5q} : {8'd0, r2q, g2q, b2q, a2q};
  wire [15:0] pq = (PACKQ != 0) ? pk : pk_n;  // the written pixel's packed value
  wire [4:0] r5 = keep[0] ? d16[15:11] : pq[15:11];
  wire [5:0] g6 = keep[1] ? d16[10:5] : pq[10:5];
  wire [4:0] b5 = keep[2] ? d16[4:0] : pq[4:0];
  wire [1:0] r2 = keep[0] ? d8[7:6] : pq[7:6];
  wire [1:0] g2 = keep[1] ? d8[5:4] : pq[5:4];
  wire [1:0] b2 = keep[2] ? d8[3:2] : pq[3:2];
  wire [1:0] a2 = keep[3] ? d8[1:0] : pq[1:0];
  reg [31:0] data_n;
  reg [3:0]  be_n;
  always @(*) begin
    if (FEATURES[F_RGB565] && fmt == 2'd1) begin
      data_n = {2{r5, g6, b5}};
      be_n   = lane[1] ? 4'b0011 : 4'b1100;
    end else if (FEATURES[F_RGBA2222] && fmt == 2'd2) begin
      data_n = {4{r2, g2, b2, a2}};
      be_n   = 4'b1000 >> lane;
    end else begin
      data_n = {cr, cg, cb, ca};
      be_n   = {~keep[0], ~keep[1], ~keep[2], ~keep[3]};
    end
  end

  // ---- write register ----
  wire wfree = pen;
  wire wv = (PP != 0) ? p3v : cur_valid;  // the written pixel is there
  assign take = cur_valid && wfree;
  assign in_ready = need_rd ? (!q_full && rd_ready) : take;
  always @(posedge clk) begin
    if (rst) begin
      wr_valid <= 1'b0;
    end else if (wfree) begin
      wr_valid <= wv;
      if (wv) begin
        wr_addr <= addr[31:2];
        wr_data <= data_n;
        wr_be   <= be_n;
      end
    end
  end
  assign idle = q_empty && !wr_valid && !p1v && !p2v && !p3v;
endmodule
