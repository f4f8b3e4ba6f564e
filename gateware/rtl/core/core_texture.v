// Texture unit (docs/protocol.md section 10), one pixel per cycle when memory keeps up:
//   reciprocal of q: count leading zeros, normalise, table of 1/midpoint (b = 10), one
//   Newton-Raphson step (k = 1);  texel coordinates tu = (s*y) >> (43 - n - wl) (1/4096 texel);
//   addressing REPEAT / CLAMP / MIRROR per axis;  nearest (one texel) or bilinear (four texels,
//   each index addressed separately) fetches;  texels expanded to 8 bits;  the bilinear weights
//   of section 10.4, done as two exact linear steps;  MODULATE (div255 of texel * colour) or
//   DECAL. A texel that the pixel ahead still waits for is not read again: its response is shared.
// Pixels flow through a stalling pipeline (coordinates, addresses) into a fetch step that issues
// the texel reads, then wait in a read queue for their words. Pixel record in: the depth stage's
// {q, t, s, rgba, yl, xl, z, idx}; out: the colour stage's {yl, xl, idx, rgba}.
module core_texture #(
    parameter integer AW = 2,  // log2 of pixels whose texels are in flight
    parameter integer CACHE = 0,  // texel cache (block RAM)
    parameter integer IDX_W = 20,
    parameter integer ADDR_W = 32
) (
    input  wire         clk,
    input  wire         rst,
    input  wire [27:0]  tex16,       // TEX_BASE / 16
    input  wire [3:0]   wl,          // log2 width, 3..10
    input  wire [3:0]   hl,
    input  wire [1:0]   wrap_s,      // 0 REPEAT, 1 CLAMP, 2 MIRROR
    input  wire [1:0]   wrap_t,
    input  wire         bilinear,
    input  wire [1:0]   tfmt,        // 0 RGBA8888, 1 RGB565, 2 RGBA2222
    input  wire         decal,
    input  wire         inval,       // forget the cached texels (a draw that does not continue the last)
    input  wire         cache_en,    // use the cache (off in serial mode)
    input  wire         in_valid,
    output wire         in_ready,
    input  wire [IDX_W+155:0] in_pix,
    output reg          out_valid,
    input  wire         out_ready,
    output reg  [IDX_W+35:0] out_pix,
    output wire         rd_valid,
    input  wire         rd_ready,
    output wire [29:0]  rd_addr,
    input  wire         rsp_valid,
    input  wire [31:0]  rsp_data,
    output wire         idle,
    output wire         textured     // a pixel left the unit this cycle
);
  // ---------------------------------------------------------------- coordinate pipeline
  wire en;  // the coordinate pipeline advances

`include "core_addr.vh"
  localparam integer PAY = IDX_W + 36;  // {yl, xl, idx, rgba}
  // Pixels enter through a two-entry FIFO whose room is registered state: the unit's readiness
  // (stage 5's cache hits, a block RAM read) reaches back into the depth stage and the rasteriser
  // no more (the ULX3S clock, docs/gateware.md "Clock estimate").
  // The FIFO also holds q's leading zeros (counted on the way in), so that the count and the
  // normalising shift in front of the reciprocal table are not one clock's work.
  function [5:0] clz32(input [31:0] v);
    integer k;
    begin
      clz32 = 6'd32;
      for (k = 0; k < 32; k = k + 1)
        if (v[k]) clz32 = 6'(31 - k);
    end
  endfunction
  wire [5:0]        in_n_in = clz32(in_pix[IDX_W+155:IDX_W+124]);
  // The two entries stay where they were written and the head is read through a pointer, so that
  // `en` (which ends the memory port's grant cone) enables only the pointer and the count, not the
  // 181-bit head register a shifting FIFO (core_fifo2) moves on every pop (the ULX3S clock,
  // docs/gateware.md "The texture unit's cones").
  reg  [IDX_W+160:0] fq0, fq1;
  reg  [1:0]        fn;        // entries held
  reg               fwp, frp;  // the entry written next, the head
  wire              f_valid = (fn != 2'd0);
  wire              f_push = in_valid && in_ready;
  wire              f_pop = en && f_valid;
  assign in_ready = (fn != 2'd2);
  always @(posedge clk) begin
    if (rst) begin
      fn <= 2'd0; fwp <= 1'b0; frp <= 1'b0;
    end else begin
      fn <= fn + {1'b0, f_push} - {1'b0, f_pop};
      if (f_push) fwp <= !fwp;
      if (f_pop) frp <= !frp;
    end
    if (f_push && !fwp) fq0 <= {in_n_in[4:0], in_pix};
    if (f_push && fwp) fq1 <= {in_n_in[4:0], in_pix};
  end
  wire [IDX_W+155:0] f_pix;
  wire [4:0]        in_n;
  assign {in_n, f_pix} = frp ? fq1 : fq0;
  wire [31:0] in_q = f_pix[IDX_W+155:IDX_W+124];
  wire [31:0] in_t = f_pix[IDX_W+123:IDX_W+92];
  wire [31:0] in_s = f_pix[IDX_W+91:IDX_W+60];
  wire [PAY-1:0] in_pay = {f_pix[IDX_W+27:IDX_W+24], f_pix[IDX_W-1:0], f_pix[IDX_W+59:IDX_W+28]};

  wire [31:0] in_m = in_q << in_n;

  // The block RAMs (this table, the texel cache) are read on every clock, not on `en`: `en` ends
  // the memory port's grant cone, and as the block RAMs' clock enables it took that cone through
  // a 2 ns net into a block (`disp_frame_addr` -> the cache's banks, 18.4 ns by the ULX3S clock
  // estimate, docs/gateware.md "The texture cache's fill target"). While the pipeline stands the
  // read answers the next pixel's address, so the word the standing pixel read is kept in a
  // register (`hu`: the pipeline stood last clock, the kept word is the one to use).
  reg         hu;
  always @(posedge clk) hu <= !en;
  wire [31:0] y0r, y0;
  reg  [31:0] y0h;
  core_recip_rom rom (.clk(clk), .en(1'b1), .addr(in_m[30:21]), .y(y0r));
  assign y0 = hu ? y0h : y0r;
  always @(posedge clk) y0h <= y0;

  // stage 1: normalised q; the table entry arrives with it
  reg        v1, qz1;
  reg [4:0]  n1;
  reg [31:0] m1, s1, t1;
  reg [PAY-1:0] pay1;
  // stage 1b: the table entry in flip-flops. The block RAM's clock-to-output (5.8 ns) and its
  // long net ended in the Newton step's multiply and its adders (`rom.y` -> `p2`, 19.0 ns by the
  // ULX3S clock estimate, docs/gateware.md "The texture unit's cones"); the multiply now starts at
  // a register. A clock of latency a pixel, none of throughput (one enable moves every stage).
  reg        v1b, qz1b;
  reg [4:0]  n1b;
  reg [31:0] m1b, y01b, s1b, t1b;
  reg [PAY-1:0] pay1b;
  // stage 2: p = m * y0
  reg        v2, qz2;
  reg [4:0]  n2;
  reg [63:0] p2;
  reg [31:0] y02, s2, t2;
  reg [PAY-1:0] pay2;
  // stage 2b: 2 - M y0, negated in a clock of its own (its 64-bit carry chain and the multiply
  // behind it were 17.8 ns by the ULX3S clock estimate, `p2` -> `yt3`)
  reg        v2b, qz2b;
  reg [4:0]  n2b;
  reg [31:0] tnr2b, y02b, s2b, t2b;
  reg [PAY-1:0] pay2b;
  // stage 3: y0 * (2 - M y0)
  reg        v3, qz3;
  reg [4:0]  n3;
  reg [63:0] yt3;
  reg [31:0] s3, t3;
  reg [PAY-1:0] pay3;
  // stage 4: s * y, t * y
  reg        v4, qz4;
  reg [4:0]  n4;
  reg signed [63:0] su4, tv4;
  reg [PAY-1:0] pay4;

  wire [63:0] negp = 64'd0 - p2;
  wire [31:0] tnr = negp[63:32];                            // 2 - M y as u1.31
  wire [32:0] ysh = yt3[63:31];
  wire [31:0] ynr = ysh[32] ? 32'hFFFFFFFF : ysh[31:0];   // min(2^32 - 1, (y t) >> 31)
  wire unused_low = &{1'b0, yt3[30:0], negp[31:0], in_n_in[5], f_pix[IDX_W+23:IDX_W]};  // depth: not here

  // Only the valid bits are reset: the data registers take `en` alone as their clock enable, not
  // `en` and the reset through a LUT and the slice's LSR (the ULX3S clock: `en` ends the memory
  // port's grant cone, docs/gateware.md "The texture unit's cones"); they matter only when valid.
  always @(posedge clk) begin
    if (rst) begin
      v1 <= 1'b0; v1b <= 1'b0; v2 <= 1'b0; v2b <= 1'b0; v3 <= 1'b0; v4 <= 1'b0;
    end else if (en) begin
      v1 <= f_valid; v1b <= v1; v2 <= v1b; v2b <= v2; v3 <= v2b; v4 <= v3;
    end
    if (en) begin
      qz1 <= (in_q == 32'd0); n1 <= in_n; m1 <= in_m; s1 <= in_s; t1 <= in_t;
      pay1 <= in_pay;
      qz1b <= qz1; n1b <= n1; m1b <= m1; y01b <= y0; s1b <= s1; t1b <= t1;
      pay1b <= pay1;
      qz2 <= qz1b; n2 <= n1b; p2 <= {32'd0, m1b} * {32'd0, y01b}; y02 <= y01b; s2 <= s1b;
      t2 <= t1b; pay2 <= pay1b;
      qz2b <= qz2; n2b <= n2; tnr2b <= tnr; y02b <= y02; s2b <= s2; t2b <= t2; pay2b <= pay2;
      qz3 <= qz2b; n3 <= n2b; yt3 <= {32'd0, y02b} * {32'd0, tnr2b}; s3 <= s2b; t3 <= t2b;
      pay3 <= pay2b;
      qz4 <= qz3; n4 <= n3; su4 <= $signed(s3) * $signed({32'd0, ynr});
      tv4 <= $signed(t3) * $signed({32'd0, ynr}); pay4 <= pay3;
    end
  end

  // ---------------------------------------------------------------- addressing (stage 5)
  wire [5:0] shu = 6'd43 - {1'b0, n4} - {2'd0, wl};
  wire [5:0] shv = 6'd43 - {1'b0, n4} - {2'd0, hl};
  wire signed [63:0] tu = qz4 ? 64'sd0 : (su4 >>> shu);
  wire signed [63:0] tv = qz4 ? 64'sd0 : (tv4 >>> shv);
  wire signed [63:0] up = bilinear ? tu - 64'sd2048 : tu;
  wire signed [63:0] vp = bilinear ? tv - 64'sd2048 : tv;
  // i1 = i0 + 1 from its own adder ((up + 4096) >>> 12), beside i0's rather than after it
  wire signed [63:0] up1 = bilinear ? tu + 64'sd2048 : tu + 64'sd4096;
  wire signed [63:0] vp1 = bilinear ? tv + 64'sd2048 : tv + 64'sd4096;

  // Two stages between the products and the addresses (the ULX3S clock, docs/gateware.md "Clock
  // estimate"): stage 4a holds the integer texel coordinates (the shifts and adders end there),
  // stage 4w the wrapped ones; stage 5 adds the addresses and looks the texels up in the cache.
  reg        v4a, v4w;
  reg signed [51:0] i0a, i1a, j0a, j1a;
  reg [7:0]  fua, fva, fuw, fvw;
  reg [9:0]  iaw, ibw, jaw, jbw;
  reg [PAY-1:0] pay4a, pay4w;
  wire [7:0] fu = fuw;
  wire [7:0] fv = fvw;

  // REPEAT / CLAMP / MIRROR with no adder or shifter (lg is 3..10: the register file clamps it), so
  // the cache's lookup address is a few LUTs after stage 4a (the ULX3S clock, docs/gateware.md "The
  // texture unit's cones"): i >>> lg is nonzero exactly when a bit of i at lg or above is set, and
  // MIRROR's k = i mod 2 size is at least size exactly when bit lg of i is set, when 2 size - 1 - k
  // is the complement of i's low lg bits.
  function [9:0] wrap(input signed [51:0] i, input [1:0] mode, input [3:0] lg);
    reg [51:0] low;  // the bits below lg
    reg big;
    begin
      low = ~(52'hF_FFFF_FFFF_FFFF << lg);
      big = |(i & ~low);
      case (mode)
        2'd1: wrap = i[51] ? 10'd0 : big ? low[9:0] : i[9:0];
        2'd2: wrap = (i[6'(lg)] ? ~i[9:0] : i[9:0]) & low[9:0];
        default: wrap = i[9:0] & low[9:0];
      endcase
    end
  endfunction
  wire [9:0] ia_n = wrap(i0a, wrap_s, wl), ib_n = wrap(i1a, wrap_s, wl);  // stage 4w's, next
  wire [9:0] ja_n = wrap(j0a, wrap_t, hl), jb_n = wrap(j1a, wrap_t, hl);
  always @(posedge clk) begin
    if (rst) begin
      v4a <= 1'b0; v4w <= 1'b0;
    end else if (en) begin
      v4a <= v4; v4w <= v4a;
    end
    if (en) begin
      i0a <= 52'(up >>> 12); i1a <= 52'(up1 >>> 12);
      j0a <= 52'(vp >>> 12); j1a <= 52'(vp1 >>> 12);
      fua <= bilinear ? up[11:4] : 8'd0;
      fva <= bilinear ? vp[11:4] : 8'd0;
      pay4a <= pay4;
      iaw <= ia_n; ibw <= ib_n;
      jaw <= ja_n; jbw <= jb_n;
      fuw <= fua; fvw <= fva; pay4w <= pay4a;
    end
  end
  wire [9:0] ia = iaw, ib = ibw, ja = jaw, jb = jbw;

  function [31:0] taddr(input [27:0] base, input [9:0] i, input [9:0] j, input [3:0] lg, input [1:0] f);
    reg [19:0] off;
    begin
      off = ({10'd0, j} << lg) | {10'd0, i};
      taddr = byte_addr(base, (f == 2'd0) ? {2'd0, off, 2'd0} : (f == 2'd1) ? {3'd0, off, 1'd0} : {4'd0, off});
    end
  endfunction
  wire [31:0] a00 = taddr(tex16, ia, ja, wl, tfmt), a10 = taddr(tex16, ib, ja, wl, tfmt);
  wire [31:0] a01 = taddr(tex16, ia, jb, wl, tfmt), a11 = taddr(tex16, ib, jb, wl, tfmt);

  // stage 5 registers: the fetch step's work
  reg         v5, bil5;
  // Coordinates shared with the pixel ahead (the one in stage 5 as this one entered it, pushed
  // into the read queue just before this one): mi[{a, b}] says this pixel's i_a equals that
  // pixel's i_b (a, b: 0 for i0, 1 for i1), mj the same for j; adj5: there was such a pixel (and
  // the cache is on: serial mode shares nothing).
  reg         adj5;
  reg  [3:0]  mi5, mj5;
  reg [29:0]  w00, w10, w01, w11;
  reg [7:0]   lanes5, fu5, fv5;
  reg [9:0]   ia5, ib5, ja5, jb5;
  reg [PAY-1:0] pay5;

  // the texel read queue's size, and the response's target (defined with the queue below)
  localparam integer QA = (AW < 1) ? 1 : AW;  // at least two pixels in flight
  localparam integer N = 1 << QA;
  localparam integer IW = PAY + 8 + 8 + 8 + 1;
  wire [1:0]  fslot;
  wire [1:0]  f_bank;  // the response's texel: its bank, entry in the bank and tag
  wire [10:0] f_idx;
  wire [6:0]  f_tag;

  // ---------------------------------------------------------------- texel cache (CACHE = 1)
  // Four banks by texel parity ({j & 1, i & 1}: the four texels of a bilinear sample are in four
  // banks, or are the same texel), each holding raw words for eight texel rows of any width
  // (index: j bits [2:1] and i bits [9:1]; tag: j >> 3), so the rows a span samples are still
  // there when the walk comes back on the next row. A pixel's four texels are looked up as it
  // enters stage 5 and its misses are filled by their responses. An entry is valid when its epoch
  // is the current one: `inval` (a draw that does not continue the last) starts a new epoch, and
  // every 256 epochs the banks are swept so an old epoch cannot come back. `cache_en` off (serial
  // mode) bypasses the cache.
  wire [3:0]   hit5;      // slot k (00, 10, 01, 11 as bits 3 .. 0) hits
  wire [127:0] hdata5;    // the words of the slots that hit
  wire         sweeping;  // the cache is being swept: the pipeline waits
  function [9:0] slot_i(input k0, input [9:0] ia_, input [9:0] ib_);  // k0: slot bit 0
    slot_i = k0 ? ib_ : ia_;
  endfunction
  function [9:0] slot_j(input k1, input [9:0] ja_, input [9:0] jb_);  // k1: slot bit 1
    slot_j = k1 ? jb_ : ja_;
  endfunction
  generate
    if (CACHE != 0) begin : cache
      (* ram_style = "block", no_rw_check *) reg [46:0] bank0[0:2047];
      (* ram_style = "block", no_rw_check *) reg [46:0] bank1[0:2047];
      (* ram_style = "block", no_rw_check *) reg [46:0] bank2[0:2047];
      (* ram_style = "block", no_rw_check *) reg [46:0] bank3[0:2047];
      reg [46:0]  rd0, rd1, rd2, rd3;   // {epoch, tag, word}
      reg [6:0]   tg0, tg1, tg2, tg3;   // the tags asked for
      reg [7:0]   epoch;
      reg [11:0]  sweep;                // bit 11: sweeping; [10:0] the entry
      assign sweeping = sweep[11];
      // lookup: bank {jp, ip} reads the pixel's texel with those parities
      // (read as the pixel enters stage 4w; the hits and words are registered into stage 5, so
      // the block RAM's read time ends there, not in the enable of the whole pipeline)
      wire [9:0] li0 = (ia_n[0] == 1'b0) ? ia_n : ib_n, lj0 = (ja_n[0] == 1'b0) ? ja_n : jb_n;  // bank 0: jp 0, ip 0
      wire [9:0] li1 = (ia_n[0] == 1'b1) ? ia_n : ib_n;                                        // bank 1: jp 0, ip 1
      wire [9:0] lj2 = (ja_n[0] == 1'b1) ? ja_n : jb_n;                                        // bank 2: jp 1, ip 0
      // entry of texel (i, j) in its bank: {j[2:1], i[9:1]}
      wire [10:0] x0 = {lj0[2:1], li0[9:1]}, x1 = {lj0[2:1], li1[9:1]};
      wire [10:0] x2 = {lj2[2:1], li0[9:1]}, x3 = {lj2[2:1], li1[9:1]};
      // fill: the response's texel, from the request-order queue's head (a register)
      wire [1:0] fbank = f_bank;
      wire [10:0] fidx = sweeping ? sweep[10:0] : f_idx;
      wire [46:0] fword = sweeping ? {epoch - 8'd1, 39'd0} : {epoch, f_tag, rsp_data};
      wire        fill = (rsp_valid && cache_en) || sweeping;
      wire unused_parity = &{1'b0, li0[0], lj0[0], li1[0], lj2[0]};
      always @(posedge clk) begin
        if (fill && (sweeping || fbank == 2'd0)) bank0[fidx] <= fword;
        if (fill && (sweeping || fbank == 2'd1)) bank1[fidx] <= fword;
        if (fill && (sweeping || fbank == 2'd2)) bank2[fidx] <= fword;
        if (fill && (sweeping || fbank == 2'd3)) bank3[fidx] <= fword;
        rd0 <= bank0[x0];  // every clock (`hu`, above)
        rd1 <= bank1[x1];
        rd2 <= bank2[x2];
        rd3 <= bank3[x3];
        if (en) begin
          tg0 <= lj0[9:3];
          tg1 <= lj0[9:3];
          tg2 <= lj2[9:3];
          tg3 <= lj2[9:3];
        end
      end
      // The read is a clock before the pixel's stage 5 (where the old design read), so the fills
      // that land between the read and stage 5 (the responses of the pixel ahead, the texels it
      // shares with this one) are caught here, or it would miss them (bilinear, 0.636 -> 0.566
      // px/clk on the core bench without this).
      // The entries as the pixel in stage 4w sees them: read as it entered (rd_k), then kept in
      // h_k with the fills since (the block RAM reads the next pixel's entries meanwhile).
      reg [10:0]  xr0, xr1, xr2, xr3;   // the entries read
      reg [46:0]  h0, h1, h2, h3;
      // (compared with the entries read, registered: a fill in the clock of the read itself is
      // not caught, as before)
      wire [3:0]  snp = {4{fill && !sweeping}} & {fbank == 2'd3 && fidx == xr3, fbank == 2'd2 && fidx == xr2,
                                                 fbank == 2'd1 && fidx == xr1, fbank == 2'd0 && fidx == xr0};
      wire [46:0] e0 = hu ? h0 : rd0, e1 = hu ? h1 : rd1;
      wire [46:0] e2 = hu ? h2 : rd2, e3 = hu ? h3 : rd3;
      always @(posedge clk) begin
        if (en) begin
          xr0 <= x0; xr1 <= x1; xr2 <= x2; xr3 <= x3;
        end
        h0 <= snp[0] ? fword : e0;
        h1 <= snp[1] ? fword : e1;
        h2 <= snp[2] ? fword : e2;
        h3 <= snp[3] ? fword : e3;
      end
      always @(posedge clk) begin
        if (rst) begin
          epoch <= 8'd1;
          sweep <= {1'b1, 11'd0};  // power on: mark every entry old
        end else if (sweeping) begin
          sweep <= (sweep[10:0] == 11'h7FF) ? 12'd0 : sweep + 12'd1;
        end else if (inval) begin
          epoch <= epoch + 8'd1;
          if (epoch == 8'hFF) sweep <= {1'b1, 11'd0};  // epoch 0 next: forget every older one
        end
      end
      wire [3:0] bhit = {e3[46:39] == epoch && e3[38:32] == tg3, e2[46:39] == epoch && e2[38:32] == tg2,
                         e1[46:39] == epoch && e1[38:32] == tg1, e0[46:39] == epoch && e0[38:32] == tg0} &
                        {4{cache_en}};
      // slot k's bank: {j parity, i parity} of its texel
      wire [1:0] sb00 = {ja[0], ia[0]}, sb10 = {ja[0], ib[0]}, sb01 = {jb[0], ia[0]}, sb11 = {jb[0], ib[0]};
      function [31:0] bw(input [1:0] b, input [31:0] d0, input [31:0] d1, input [31:0] d2, input [31:0] d3);
        bw = (b == 2'd0) ? d0 : (b == 2'd1) ? d1 : (b == 2'd2) ? d2 : d3;
      endfunction
      wire [3:0] hit_n = {bhit[sb00], bhit[sb10], bhit[sb01], bhit[sb11]};
      wire [127:0] hdata_n = {bw(sb00, e0[31:0], e1[31:0], e2[31:0], e3[31:0]),
                       bw(sb10, e0[31:0], e1[31:0], e2[31:0], e3[31:0]),
                       bw(sb01, e0[31:0], e1[31:0], e2[31:0], e3[31:0]),
                       bw(sb11, e0[31:0], e1[31:0], e2[31:0], e3[31:0])};
      reg [3:0]   hit_r;
      reg [127:0] hdata_r;
      always @(posedge clk) begin
        if (en) begin
          hit_r   <= hit_n;
          hdata_r <= hdata_n;
        end
      end
      assign hit5 = hit_r;
      assign hdata5 = hdata_r;
    end else begin : no_cache
      assign hit5 = 4'd0;
      assign hdata5 = 128'd0;
      assign sweeping = 1'b0;
      wire unused_cache = &{1'b0, inval, cache_en, f_bank, f_idx, f_tag};
    end
  endgenerate

  // ---------------------------------------------------------------- misses to memory
  // slots 00 10 01 11 as bits 3 2 1 0; nearest needs slot 00 only
  reg  [3:0]  asked;      // slots of this pixel already requested
  reg         pushed;     // this pixel's queue entry exists
  wire        q_full;
  wire [3:0]  miss5 = (bil5 ? 4'b1111 : 4'b1000) & ~hit5;
  // A texel the pixel ahead still waits for (its own read or one it shares) is not read again:
  // at half a texel per pixel the next pixel, looked up before that read's response lands, misses
  // the same texels, and each would otherwise go to memory two to four times (docs/gateware.md
  // "Where bilinear loses its clocks"). Decided as the entry is pushed, from registers only (the
  // response of this clock is taken into the entry instead, below), so rd_valid does not wait for
  // the response routing.
  wire [3:0]  shr_now;    // slots shared (bit 3 - k for slot k)
  wire [4*(QA+2)-1:0] shr_src;  // slot k's source {entry, slot} at [k*(QA+2) +: QA+2]
  reg  [3:0]  shr_r;      // shr_now as the entry was pushed
  wire [3:0]  need = miss5 & ~(pushed ? shr_r : shr_now);
  wire [3:0]  rem = need & ~asked;
  wire [1:0]  slot = rem[3] ? 2'd0 : rem[2] ? 2'd1 : rem[1] ? 2'd2 : 2'd3;
  wire        can = v5 && (pushed || !q_full) && !sweeping;
  wire        push = v5 && !pushed && !q_full && !sweeping;
  assign rd_valid = can && (rem != 4'd0);
  assign rd_addr  = (slot == 2'd0) ? w00 : (slot == 2'd1) ? w10 : (slot == 2'd2) ? w01 : w11;
  wire [3:0]  slot_bit = 4'b1000 >> slot;
  // done5 = can && (rem_after == 0), written so that rd_ready (the memory port's grant, late in
  // the clock) is one gate from `en`: with one slot left the grant is of that slot.
  wire        rem_one = (rem == 4'b1000) || (rem == 4'b0100) || (rem == 4'b0010) || (rem == 4'b0001);
  wire        done5 = can && ((rem == 4'd0) || (rem_one && rd_ready));
  assign en = (!v5 || done5) && !sweeping;

  always @(posedge clk) begin
    if (rst) begin
      v5     <= 1'b0;
      asked  <= 4'd0;
      pushed <= 1'b0;
    end else begin
      if (en) begin
        v5     <= v4w;
        asked  <= 4'd0;
        pushed <= 1'b0;
      end else begin
        if (push) pushed <= 1'b1;
        if (rd_valid && rd_ready) asked <= asked | slot_bit;
      end
    end
    // the data: `en` alone (see stage 1)
    if (en) begin
      bil5   <= bilinear;
      adj5   <= v5 && cache_en;
      mi5    <= {ib == ib5, ib == ia5, ia == ib5, ia == ia5};
      mj5    <= {jb == jb5, jb == ja5, ja == jb5, ja == ja5};
      w00    <= a00[31:2];
      w10    <= a10[31:2];
      w01    <= a01[31:2];
      w11    <= a11[31:2];
      lanes5 <= {a00[1:0], a10[1:0], a01[1:0], a11[1:0]};
      fu5    <= fu;
      fv5    <= fv;
      ia5    <= ia;
      ib5    <= ib;
      ja5    <= ja;
      jb5    <= jb;
      pay5   <= pay4w;
    end
    if (!en && push) shr_r <= shr_now;
  end

  // ---------------------------------------------------------------- texel read queue
  // An entry per pixel: the words of the slots that hit, and the slots still to come from memory
  // (responses arrive in request order: the oldest entry with slots outstanding takes each).
  // An entry's shared slots (cp) wait for the response to another entry's read: src names it
  // ({entry, slot} per slot, as shr_src).
  reg [IW-1:0]  items[0:N-1];
  reg [127:0]   words[0:N-1];
  reg [3:0]     miss[0:N-1];
  reg [3:0]     cp[0:N-1];
  reg [4*(QA+2)-1:0] src[0:N-1];
  reg [QA:0]    wp, rp;
  assign q_full = (wp - rp) == N[QA:0];
  wire [IW-1:0] hitem = items[rp[QA-1:0]];
  wire [127:0]  hword = words[rp[QA-1:0]];
  wire          hvalid = (wp != rp) && (miss[rp[QA-1:0]] == 4'd0) && (cp[rp[QA-1:0]] == 4'd0);
  // The last pushed pixel's slots: lpend[s] says its slot s (number s: 0 = 00, 1 = 10, 2 = 01,
  // 3 = 11) still waits for memory (its own read or one it shares): the read of slot ls[s] of entry
  // le[s], which cannot have left the queue. A register, set at the push and cleared by that read's
  // response, rather than looked up in `miss`: the lookup put 23 cells between le and the
  // pipeline's enable (22.7 ns by the ULX3S clock estimate).
  reg  [3:0]    lpend;
  reg  [QA-1:0] le[0:3];
  reg  [1:0]    ls[0:3];
  // slot k of this pixel takes the first slot s of the last one holding the same texel and pending
  function [QA+2:0] share_k(input [1:0] k, input [3:0] mi, input [3:0] mj, input [3:0] pend,
                            input [4*(QA+2)-1:0] lsrc);
    integer sk;
    begin
      share_k = {1'b0, {(QA+2){1'b0}}};
      for (sk = 3; sk >= 0; sk = sk - 1)
        if (mi[{k[0], 1'(sk)}] && mj[{k[1], 1'(sk >> 1)}] && pend[sk])
          share_k = {1'b1, lsrc[sk*(QA+2) +: QA+2]};
    end
  endfunction
  wire [4*(QA+2)-1:0] lsrc = {le[3], ls[3], le[2], ls[2], le[1], ls[1], le[0], ls[0]};
  wire [QA+2:0] sh0 = share_k(2'd0, mi5, mj5, lpend, lsrc), sh1 = share_k(2'd1, mi5, mj5, lpend, lsrc);
  wire [QA+2:0] sh2 = share_k(2'd2, mi5, mj5, lpend, lsrc), sh3 = share_k(2'd3, mi5, mj5, lpend, lsrc);
  assign shr_now = {4{adj5}} & miss5 & {sh0[QA+2], sh1[QA+2], sh2[QA+2], sh3[QA+2]};
  assign shr_src = {sh3[QA+1:0], sh2[QA+1:0], sh1[QA+1:0], sh0[QA+1:0]};
  wire          pop;
  // The reads asked for, in request order: the responses come in that order, so the queue's head
  // names the next response's entry and slot and the texel it fills in the cache. The head is a
  // register (rq[rqr], written a clock ahead), so the cache's fill snoop compares a flip-flop with
  // the entries read; it was the oldest entry with slots outstanding, searched through the read
  // queue's pointers and misses in the response's clock (`wp` -> the snoop `sn0`, 19.3 ns by the
  // ULX3S clock estimate, docs/gateware.md "The texture cache's fill target"). An entry's reads are
  // its slots in order 00 10 01 11, all asked for before the next entry's, so the head is that
  // search's answer. At most four reads an entry are in flight: 4N entries never overflow.
  localparam integer RA = QA + 2;
  localparam integer RW = QA + 2 + 2 + 11 + 7;  // {entry, slot, bank, index in the bank, tag}
  reg  [RW-1:0] rq[0:(1 << RA)-1];
  reg  [RA-1:0] rqw, rqr;
  reg  [RW-1:0] rqh;  // rq[rqr]
  wire          rq_push = rd_valid && rd_ready;
  wire [9:0]    rq_i = slot_i(slot[0], ia5, ib5), rq_j = slot_j(slot[1], ja5, jb5);
  wire [QA-1:0] rq_e = pushed ? QA'(wp[QA-1:0] - 1'b1) : wp[QA-1:0];  // stage 5's entry
  wire [RW-1:0] rq_d = {rq_e, slot, rq_j[0], rq_i[0], rq_j[2:1], rq_i[9:1], rq_j[9:3]};
  wire [RA-1:0] rqr1 = rqr + 1'b1;
  always @(posedge clk) begin
    if (rst) begin
      rqw <= 0; rqr <= 0;
    end else begin
      if (rq_push) rqw <= rqw + 1'b1;
      if (rsp_valid) rqr <= rqr1;
    end
    if (rq_push) rq[rqw] <= rq_d;
    // the head of the next clock: the entry written now when it lands there
    rqh <= (rq_push && rqw == (rsp_valid ? rqr1 : rqr)) ? rq_d : rsp_valid ? rq[rqr1] : rq[rqr];
  end
  wire [QA-1:0] fe = rqh[RW-1:RW-QA];
  wire [3:0] fmiss = miss[fe];
  assign fslot = rqh[21:20];
  assign {f_bank, f_idx, f_tag} = rqh[19:0];
  // the response of this clock: {entry, slot}
  wire [QA+1:0] rsrc = {fe, fslot};
  integer qe, qs, pk;
  reg [127:0] pw;       // the pushed entry's words
  reg [3:0]   pcp;      // its slots still waiting for a shared response
  always @(*) begin
    pw = hdata5;
    pcp = shr_now;
    for (pk = 0; pk < 4; pk = pk + 1)
      // a shared read answered in the push's own clock: its word goes in now
      if (shr_now[3 - pk] && rsp_valid && shr_src[pk*(QA+2) +: QA+2] == rsrc) begin
        pw[(3 - pk)*32 +: 32] = rsp_data;
        pcp[3 - pk] = 1'b0;
      end
  end
  always @(posedge clk) begin
    if (rst) begin
      wp <= 0; rp <= 0;
      lpend <= 4'd0;
    end else begin
      for (qs = 0; qs < 4; qs = qs + 1)
        if (rsp_valid && {le[qs], ls[qs]} == rsrc) lpend[qs] <= 1'b0;
      if (rsp_valid) begin
        case (fslot)
          2'd0: words[fe][127:96] <= rsp_data;
          2'd1: words[fe][95:64] <= rsp_data;
          2'd2: words[fe][63:32] <= rsp_data;
          default: words[fe][31:0] <= rsp_data;
        endcase
        miss[fe] <= fmiss & ~(4'b1000 >> fslot);
        // the entries sharing that read take the word too
        for (qe = 0; qe < N; qe = qe + 1)
          for (qs = 0; qs < 4; qs = qs + 1)
            if (cp[qe][3 - qs] && src[qe][qs*(QA+2) +: QA+2] == rsrc) begin
              words[qe][(3 - qs)*32 +: 32] <= rsp_data;
              cp[qe][3 - qs] <= 1'b0;
            end
      end
      if (push) begin
        items[wp[QA-1:0]] <= {bil5, lanes5, fu5, fv5, pay5};
        words[wp[QA-1:0]] <= pw;
        miss[wp[QA-1:0]]  <= need;
        cp[wp[QA-1:0]]    <= pcp;
        src[wp[QA-1:0]]   <= shr_src;
        wp <= wp + 1'b1;
        // what the next pixel may share: the slots this one reads, or shares and still waits for
        for (qs = 0; qs < 4; qs = qs + 1) begin
          lpend[qs] <= need[3 - qs] || pcp[3 - qs];
          le[qs] <= need[3 - qs] ? wp[QA-1:0] : shr_src[qs*(QA+2) + 2 +: QA];
          ls[qs] <= need[3 - qs] ? 2'(qs) : shr_src[qs*(QA+2) +: 2];
        end
      end
      if (pop) rp <= rp + 1'b1;
    end
  end

  // ---------------------------------------------------------------- filter and combine
  function [31:0] texel(input [31:0] w, input [1:0] lane, input [1:0] f);
    reg [15:0] h;
    reg [7:0] b;
    begin
      h = lane[1] ? w[15:0] : w[31:16];
      b = (lane == 2'd0) ? w[31:24] : (lane == 2'd1) ? w[23:16] : (lane == 2'd2) ? w[15:8] : w[7:0];
      case (f)
        2'd1: texel = {h[15:11], h[15:13], h[10:5], h[10:9], h[4:0], h[4:2], 8'hFF};
        2'd2: texel = {{4{b[7:6]}}, {4{b[5:4]}}, {4{b[3:2]}}, {4{b[1:0]}}};
        default: texel = w;
      endcase
    end
  endfunction
  wire        hbil = hitem[PAY+24];
  wire [7:0]  hl00 = hitem[PAY+23:PAY+16];
  wire [7:0]  hfu = hitem[PAY+15:PAY+8], hfv = hitem[PAY+7:PAY];
  wire [PAY-1:0] hpay = hitem[PAY-1:0];
  wire [31:0] c00 = texel(hword[127:96], hl00[7:6], tfmt);
  wire [31:0] c10 = hbil ? texel(hword[95:64], hl00[5:4], tfmt) : c00;
  wire [31:0] c01 = hbil ? texel(hword[63:32], hl00[3:2], tfmt) : c00;
  wire [31:0] c11 = hbil ? texel(hword[31:0], hl00[1:0], tfmt) : c00;

  // The filter is three registered steps behind the queue head (the ULX3S clock, docs/gateware.md
  // "Clock estimate"), all moved by one enable, so a pixel a clock still leaves when the colour
  // stage takes one a clock:
  //   f1: the four texels, expanded;  f2: the step along u, (p00 (256-u) + p10 u) per row;
  //   f3: the step along v, rounded (section 10.4 exactly);  out: MODULATE or DECAL.
  wire fen = !out_valid || out_ready;
  assign pop = hvalid && fen;
  reg         f1v, f2v, f3v;
  reg [31:0]  f1c00, f1c10, f1c01, f1c11;
  reg [7:0]   f1u, f1v8, f2v8;
  reg [PAY-1:0] f1pay, f2pay, f3pay;
  reg [16:0]  f2a[0:3], f2b[0:3];   // per channel (0 R .. 3 A): the rows' steps along u
  reg [7:0]   f3t[0:3];             // the filtered texel
  // (c00 (256-fu) + c10 fu) (256-fv) + (c01 (256-fu) + c11 fu) fv, rounded
  function [16:0] lerp_u(input [7:0] p0, input [7:0] p1, input [7:0] u);
    lerp_u = 17'(p0) * (17'd256 - 17'(u)) + 17'(p1) * 17'(u);
  endfunction
  function [7:0] lerp_v(input [16:0] a, input [16:0] b, input [7:0] v);
    lerp_v = 8'((34'(a) * (34'd256 - 34'(v)) + 34'(b) * 34'(v) + 34'd32768) >> 16);
  endfunction
  function [7:0] div255(input [15:0] x);
    reg [16:0] y;
    begin
      y = 17'(x) + 17'd128;
      div255 = 8'((y + {8'd0, y[16:8]}) >> 8);
    end
  endfunction
  integer ch;
  always @(posedge clk) begin
    if (rst) begin
      f1v <= 1'b0; f2v <= 1'b0; f3v <= 1'b0;
    end else if (fen) begin
      f1v <= hvalid; f2v <= f1v; f3v <= f2v;
    end
    if (fen) begin
      f1c00 <= c00; f1c10 <= c10; f1c01 <= c01; f1c11 <= c11;
      f1u <= hfu; f1v8 <= hfv; f1pay <= hpay;
      for (ch = 0; ch < 4; ch = ch + 1) begin
        f2a[ch] <= lerp_u(f1c00[ch*8 +: 8], f1c10[ch*8 +: 8], f1u);
        f2b[ch] <= lerp_u(f1c01[ch*8 +: 8], f1c11[ch*8 +: 8], f1u);
        f3t[ch] <= lerp_v(f2a[ch], f2b[ch], f2v8);
      end
      f2v8 <= f1v8; f2pay <= f1pay;
      f3pay <= f2pay;
    end
  end
  wire [31:0] col = f3pay[31:0];
  wire [31:0] tex = {f3t[3], f3t[2], f3t[1], f3t[0]};
  wire [31:0] comb = decal ? tex :
                     {div255(16'(f3t[3]) * 16'(col[31:24])), div255(16'(f3t[2]) * 16'(col[23:16])),
                      div255(16'(f3t[1]) * 16'(col[15:8])), div255(16'(f3t[0]) * 16'(col[7:0]))};

  always @(posedge clk) begin
    if (rst) begin
      out_valid <= 1'b0;
    end else if (fen) begin
      out_valid <= f3v;
      if (f3v) out_pix <= {f3pay[PAY-1:32], comb};
    end
  end
  assign textured = pop;
  assign idle = !f_valid && !v1 && !v1b && !v2 && !v2b && !v3 && !v4 && !v4a && !v4w && !v5 && (wp == rp) && !f1v && !f2v && !f3v && !out_valid;
endmodule
