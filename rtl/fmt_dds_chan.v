// fmt_dds_chan -- one DDS channel engine: computes the words of SLOTS rows (a row per
// slot), one row per processing edge, with one phase adder, one amplitude product and
// one sine-table port (fmt_dds_rom2, outside: this block drives its address and takes
// the registered table word back).  fmt_dds_bank runs SLOTS = ROWS_PER_ENGINE = R and
// supplies the shared control (slot counter, delayed settings bus, delayed PN sign).
//
// Per slot c: settings registers tw (PHASE_BITS), amp (AMP_BITS, unsigned), en (1),
// written through cfg_we_i[c] / cfg_sel_i (0 tuning word, 1 amplitude, 2 enable, 3
// ignored) / cfg_data_i (LSB-aligned), at the edge where cfg_we_i[c] = 1 (the bank
// delays the settings bus per slot so that every slot sees exactly the writes made
// before the ce edge of its sample, see fmt_dds_bank).  Slots >= ACTIVE carry no row:
// tw = 0, en = 0, no output.
//
// Phase: a ring of SLOTS registers; ph[0] holds the phase of the slot processed at the
// next edge with proc_i = 1; at that edge ph[SLOTS-1] <= ph[0] + tw[slot] and the
// others move down one place (SLOTS = 1: an ordinary accumulator).  Reset: all 0.
//
// Pipeline (advances when pe_i = 1; R = 1: pe_i = ce, R > 1: every clk):
//   edge E-1 : the table latches rom[phase of slot c >> (PHASE_BITS - TABLE_ADDR)],
//            read one edge early: addr_o = ph[1] (SLOTS > 1, the ring's next slot) or
//            ph + tw (SLOTS = 1, the phase after this edge).
//   edge E   (processing of slot c = slot_i): the table's output register takes that
//            word (sine_i); a1 = (sign_i ? -amp[c] : amp[c]), 0 when en[c] = 0 or
//            proc_i = 0, is registered (AMP_MUL = 1; Booth: the digit controls of a1
//            and en[c] & proc_i).
//   edge E+1 : the product s * a1 (Booth: its two partial sums, zero when disabled)
//              and the sign.
//   edge E+2 : res = (product + rounding constant) bits [PW-1:SH] (combinational from
//              the E+1 registers), written into the staging register of slot c when
//              stg_we_i[c] = 1 (c < SLOTS-1).
// Output: at an edge with ce_i = 1, dac_o[c] <= staging[c] (c < SLOTS-1) and
// dac_o[SLOTS-1] <= res (the last slot's word computed at that very edge), so all rows
// of the engine change together, at ce edges only.
//
// Amplitude product, two forms with the same words bit for bit (AMP_MUL; default: the
// multiplier for SLOTS > 1, the time-shared engines of the core, Booth for SLOTS = 1):
// AMP_MUL = 1: one multiplier (DSP48E / ECP5 MULT18X18D), written as XST packs it: both
// operands come from registers (the table's output register and a1 = sign ? -amp :
// amp, AMP_BITS + 1 bits signed, 0 when the slot is disabled, registered at edge E), the
// product is registered at edge E+1, the rounding adder follows that register.  About
// 190 LUT6 fewer per engine than Booth (fmt_dds_bank R = 3: 1,341 against 3,141 LUT6).
// At SLOTS = 1 (30 engines, 30 multipliers) the table-to-multiplier route does not close
// 125 MHz on the ECP5 (120.5 MHz), so that build keeps Booth (138.7 MHz).
// AMP_MUL = 0, LUT only (no DSP48E): q = s * (sign ? -amp : amp) with s the
// SINE_BITS-bit signed table word and amp the AMP_BITS-bit unsigned amplitude, by
// radix-4 Booth recoding of amp (ND = AMP_BITS/2 + 1 digits d_j = a[2j] + a[2j-1] -
// 2 a[2j+1] in -2..2, a[-1] = 0, zero above the MSB), each digit's sign flipped when
// sign = 1: q = sum_j (+-d_j) s 4^j; a negative digit contributes ~m 4^j plus a 1 at
// bit 2j, placed in a free low bit of digit j+1's shifted term (the last digit is
// negative only when sign = 1: its 1 goes into the rounding constant).  The terms are
// summed in two halves registered at edge E+1 and added after it (exact: two's
// complement modulo 2^PW, and |q| < 2^(PW-1)).  No `*` operator appears, so neither
// XST nor Yosys can map it to a DSP48E.
// Rounding: r = (p + 2^(SH-1)) >> SH, p = s * amp, SH = SINE_BITS + AMP_BITS -
// DAC_BITS (round half up), and the word is sign ? -r : r; -r is computed as
// (-p + 2^(SH-1) - 1) >> SH (= floor((~p + 2^(SH-1)) / 2^SH)), so the rounding
// constant is 2^(SH-1) or 2^(SH-1) - 1 and the words of +1 and -1 are exact negatives;
// with a1 = -amp the product is -p, so the word is (s * a1 + 2^(SH-1) - sign) >> SH
// (SH = 0: the exact product s * a1).
// Range: |s| <= 2^(SINE_BITS-1) - 1 and amp <= 2^AMP_BITS - 1 give
// |r| <= 2^(DAC_BITS-1) - 1 when 2^(SH-1) < 2^(SINE_BITS-1) + 2^AMP_BITS - 1 (always
// so for DAC_BITS > AMP_BITS), so -r never overflows: no saturation is needed.
// Full amplitude (2^AMP_BITS - 1) gives a peak of (2^AMP_BITS - 1) / 2^AMP_BITS of the
// DAC range (2040 of 2047 for 16/8/12 bits).
// Twin: sim/fmt/dds_bank.py dds_bank_fixed.
`default_nettype none
`include "fmt_defaults.vh"

module fmt_dds_chan #(
    parameter PHASE_BITS = `FMT_PHASE_BITS,   // phase accumulator width
    parameter TABLE_ADDR = 10,                // sine table address bits (<= PHASE_BITS)
    parameter SINE_BITS  = `FMT_SINE_BITS,    // sine table word width (signed)
    parameter AMP_BITS   = `FMT_AMP_BITS,     // amplitude width (unsigned, >= 2)
    parameter DAC_BITS   = `FMT_DAC_BITS,     // output word width (signed), <= SINE_BITS + AMP_BITS
    parameter SLOTS      = 1,                 // rows served by this engine (time-multiplex factor R)
    parameter ACTIVE     = SLOTS,             // slots 0..ACTIVE-1 carry a row (1..SLOTS)
    parameter [PHASE_BITS-1:0] TW_RESET = 0,  // tuning word of slot 0 after reset
    parameter [PHASE_BITS-1:0] TW_STEP  = 0,  // slot c resets to TW_RESET + c * TW_STEP
    parameter SLOT_W     = (SLOTS > 1) ? $clog2(SLOTS) : 1, // width of slot_i
    parameter AMP_MUL    = (SLOTS > 1) ? 1 : 0    // amplitude product: 1 one multiplier
                                                  // (DSP48E), 0 LUT-only Booth (see header)
) (
    input  wire                          clk,
    input  wire                          rst,         // synchronous, active high
    input  wire                          pe_i,        // pipeline advance (see header)
    input  wire                          proc_i,      // process slot slot_i at this edge
    input  wire [SLOT_W-1:0]             slot_i,      // slot processed at this edge
    input  wire                          sign_i,      // PN sign of that slot's sample, 1 = -1
    // idle slots (ACTIVE..SLOTS-1) have no settings registers: their bits are not used
    /* verilator lint_off UNUSEDSIGNAL */
    input  wire [SLOTS-1:0]              cfg_we_i,    // write one setting of slot c
    input  wire [2*SLOTS-1:0]            cfg_sel_i,   // slot c at [2c +: 2]: 0 tw, 1 amp, 2 enable
    input  wire [SLOTS*PHASE_BITS-1:0]   cfg_data_i,  // slot c at [c*PHASE_BITS +: PHASE_BITS]
    /* verilator lint_on UNUSEDSIGNAL */
    output wire [TABLE_ADDR-1:0]         addr_o,      // table address (ring head, top bits)
    input  wire signed [SINE_BITS-1:0]   sine_i,      // table word of addr_o at the last pe edge
    // bit SLOTS-1 is not used: the last slot has no staging register (see header)
    /* verilator lint_off UNUSEDSIGNAL */
    input  wire [SLOTS-1:0]              stg_we_i,    // staging write of slot c (c < SLOTS-1)
    /* verilator lint_on UNUSEDSIGNAL */
    input  wire                          ce_i,        // sample strobe: outputs load at this edge
    output wire [ACTIVE*DAC_BITS-1:0]    dac_o        // slot c at [c*DAC_BITS +: DAC_BITS], signed
);

    localparam PW   = SINE_BITS + AMP_BITS;         // product width (signed)
    localparam SH   = PW - DAC_BITS;                // rounding shift
    localparam SHM1 = (SH > 0) ? SH - 1 : 0;
    localparam [PW-1:0] HALF = (SH > 0) ? ({{(PW - 1){1'b0}}, 1'b1} << SHM1) : {PW{1'b0}};
    localparam ND   = AMP_BITS / 2 + 1;             // radix-4 Booth digits of the unsigned amplitude
    localparam LO_D = (ND + 1) / 2;                 // digits summed in the low half
    // Booth rounding constant: +2^(SH-1) for +r; for -r = (~p + 2^(SH-1)) >> SH with the
    // products negated digit by digit, 2^(SH-1) - 1 plus the +1 of the top digit (always
    // "negative" then, see the header)
    localparam [PW-1:0] TOP1  = {{(PW - 1){1'b0}}, 1'b1} << (2 * (ND - 1));
    localparam [PW-1:0] RND_P = HALF;
    localparam [PW-1:0] RND_N = HALF - {{(PW - 1){1'b0}}, 1'b1} + TOP1;

    // ---------------------------------------------------------------- settings
    wire [SLOTS*PHASE_BITS-1:0] tw_all;
    wire [SLOTS*AMP_BITS-1:0]   amp_all;
    wire [SLOTS-1:0]            en_all;

    genvar c;
    generate
        for (c = 0; c < SLOTS; c = c + 1) begin : g_set
            if (c < ACTIVE) begin : g_row
                localparam [PHASE_BITS-1:0] TW_C = TW_RESET + c * TW_STEP;
                reg [PHASE_BITS-1:0] tw_q;
                reg [AMP_BITS-1:0]   amp_q;
                reg                  en_q;
                always @(posedge clk) begin
                    if (rst) begin
                        tw_q  <= TW_C;
                        amp_q <= {AMP_BITS{1'b1}};
                        en_q  <= 1'b1;
                    end else if (cfg_we_i[c]) begin
                        case (cfg_sel_i[2*c +: 2])
                            2'd0:    tw_q  <= cfg_data_i[c*PHASE_BITS +: PHASE_BITS];
                            2'd1:    amp_q <= cfg_data_i[c*PHASE_BITS +: AMP_BITS];
                            2'd2:    en_q  <= cfg_data_i[c*PHASE_BITS];
                            default: ;
                        endcase
                    end
                end
                assign tw_all[c*PHASE_BITS +: PHASE_BITS] = tw_q;
                assign amp_all[c*AMP_BITS +: AMP_BITS]    = amp_q;
                assign en_all[c]                          = en_q;
            end else begin : g_idle
                assign tw_all[c*PHASE_BITS +: PHASE_BITS] = {PHASE_BITS{1'b0}};
                assign amp_all[c*AMP_BITS +: AMP_BITS]    = {AMP_BITS{1'b0}};
                assign en_all[c]                          = 1'b0;
            end
        end
    endgenerate

    // settings of the slot processed at this edge (an R:1 multiplexer per bit)
    reg [PHASE_BITS-1:0] tw_s;
    reg [AMP_BITS-1:0]   amp_s;
    reg                  en_s;
    integer k;
    always @* begin
        tw_s  = tw_all[PHASE_BITS-1:0];
        amp_s = amp_all[AMP_BITS-1:0];
        en_s  = en_all[0];
        for (k = 1; k < SLOTS; k = k + 1) begin
            if (slot_i == k[SLOT_W-1:0]) begin
                tw_s  = tw_all[k*PHASE_BITS +: PHASE_BITS];
                amp_s = amp_all[k*AMP_BITS +: AMP_BITS];
                en_s  = en_all[k];
            end
        end
    end

    // ---------------------------------------------------------------- phase ring
    reg [SLOTS*PHASE_BITS-1:0] ph_q;   // ph[i] at [i*PHASE_BITS +: PHASE_BITS]
    wire [PHASE_BITS-1:0] ph_head = ph_q[PHASE_BITS-1:0];
    wire [PHASE_BITS-1:0] ph_next = ph_head + tw_s;


    // The table is read one edge ahead of the processing edge (its word is registered
    // twice: block-RAM latch and output register).  SLOTS > 1: the slot processed at
    // the next edge sits in ph[1]; SLOTS = 1: the phase after this edge is ph + tw.
    generate
        if (SLOTS > 1) begin : g_ring
            assign addr_o = ph_q[2*PHASE_BITS-1 -: TABLE_ADDR];
            always @(posedge clk) begin
                if (rst)         ph_q <= {(SLOTS*PHASE_BITS){1'b0}};
                else if (proc_i) ph_q <= {ph_next, ph_q[SLOTS*PHASE_BITS-1:PHASE_BITS]};
            end
        end else begin : g_acc
            assign addr_o = ph_next[PHASE_BITS-1 -: TABLE_ADDR];
            always @(posedge clk) begin
                if (rst)         ph_q <= {PHASE_BITS{1'b0}};
                else if (proc_i) ph_q <= ph_next;
            end
        end
    endgenerate

    // ---------------------------------------------------------------- product pipeline
    // res_w: the rounded, signed word of the slot processed two edges ago (see header)
    wire signed [DAC_BITS-1:0] res_w;
    generate
        if (AMP_MUL != 0) begin : g_mul
            // Edge E registers a1 = sign ? -amp : amp (signed, AMP_BITS + 1 bits; 0 when the
            // slot is disabled or not processed) and the sign; edge E+1 the product and the
            // sign; after E+1 one adder gives the rounded, signed word.
            reg signed [AMP_BITS:0] a1_q;
            reg                     sg1_q, sg2_q;
            reg signed [PW-1:0]     p_q;
            // a disabled slot (or no processing) multiplies by 0: no gate after the product
            wire [AMP_BITS:0]       amp_u = (proc_i && en_s) ? {1'b0, amp_s} : {(AMP_BITS + 1){1'b0}};
            wire signed [AMP_BITS:0] a1_d = sign_i ? -amp_u : amp_u;
            // |s * a1| <= (2^(SINE_BITS-1) - 1)(2^AMP_BITS - 1) < 2^(PW-1): PW bits hold it
            // (bit PW, the full product's extra sign bit, is not used)
            /* verilator lint_off UNUSEDSIGNAL */
            wire signed [PW:0]      prod_w = sine_i * a1_q;
            /* verilator lint_on UNUSEDSIGNAL */

            always @(posedge clk) begin
                if (rst) begin
                    a1_q  <= {(AMP_BITS + 1){1'b0}};
                    sg1_q <= 1'b0;
                    sg2_q <= 1'b0;
                    p_q   <= {PW{1'b0}};
                end else if (pe_i) begin
                    a1_q  <= a1_d;
                    sg1_q <= sign_i;
                    sg2_q <= sg1_q;
                    p_q   <= prod_w[PW-1:0];
                end
            end

            // rounding: + 2^(SH-1) for +r, + 2^(SH-1) - 1 for -r (see header; SH = 0: none, the
            // word is the exact product); the low SH bits of the sum are the fraction that the
            // rounding drops
            wire [PW-1:0]              rnd_w = (SH > 0) ? HALF - {{(PW - 1){1'b0}}, sg2_q} : {PW{1'b0}};
            /* verilator lint_off UNUSEDSIGNAL */
            wire signed [PW-1:0]       sum_w = p_q + rnd_w;
            /* verilator lint_on UNUSEDSIGNAL */
            assign res_w = sum_w[PW-1:SH];
        end else begin : g_booth
            // Edge E registers the Booth digit controls of (sign ? -amp : amp) (per digit: |d|
            // = 1, |d| = 2, negative) and en; edge E+1 the two partial sums (zero when the slot
            // is disabled); after E+1 one adder gives the rounded, signed word.
            reg [ND-1:0]         one1_q, two1_q, neg1_q;
            reg                  en1_q, sg1_q;
            reg signed [PW-1:0]  pp_lo_q, pp_hi_q;
            reg signed [PW-1:0]  pp_lo_d, pp_hi_d;
            reg [ND-1:0]         one_d, two_d, neg_d;

            wire signed [PW-1:0] s_ext = {{AMP_BITS{sine_i[SINE_BITS-1]}}, sine_i};
            wire [2*ND:0]        ax    = {{(2*ND - AMP_BITS){1'b0}}, amp_s, 1'b0};  // {0.., amp, 0}
            // rounding constant (RND_P, RND_N: see the module's localparams)
            reg [PW-1:0] m, op;
            always @* begin : c_booth
                integer j;
                // digit j of amp: bits b = {a[2j+1], a[2j], a[2j-1]}, d = a[2j] + a[2j-1] - 2 a[2j+1];
                // the sign flips every digit's sign bit (a zero digit with neg = 1 gives ~0 + 1 = 0)
                for (j = 0; j < ND; j = j + 1) begin
                    one_d[j] = ax[2*j] ^ ax[2*j+1];
                    two_d[j] = (ax[2*j+2] & ~ax[2*j+1] & ~ax[2*j]) | (~ax[2*j+2] & ax[2*j+1] & ax[2*j]);
                    neg_d[j] = ax[2*j+2] ^ sign_i;
                end
                pp_lo_d = sg1_q ? RND_N : RND_P;
                pp_hi_d = {PW{1'b0}};
                for (j = 0; j < ND; j = j + 1) begin
                    m  = one1_q[j] ? s_ext : (two1_q[j] ? {s_ext[PW-2:0], 1'b0} : {PW{1'b0}});
                    op = (neg1_q[j] ? ~m : m) << (2 * j);
                    // the +1 of digit j-1 in a free low bit (bit 2j-2) of this term
                    if (j > 0) op = op | ({{(PW - 1){1'b0}}, neg1_q[j-1]} << (2 * j - 2));
                    if (j < LO_D) pp_lo_d = pp_lo_d + op;
                    else          pp_hi_d = pp_hi_d + op;
                end
            end

            // the low SH bits of the sum are the fraction that the rounding drops
            /* verilator lint_off UNUSEDSIGNAL */
            wire signed [PW-1:0]       sum_w = pp_lo_q + pp_hi_q;
            /* verilator lint_on UNUSEDSIGNAL */
            assign res_w = sum_w[PW-1:SH];

            always @(posedge clk) begin
                if (rst) begin
                    one1_q  <= {ND{1'b0}};
                    two1_q  <= {ND{1'b0}};
                    neg1_q  <= {ND{1'b0}};
                    en1_q   <= 1'b0;
                    sg1_q   <= 1'b0;
                    pp_lo_q <= {PW{1'b0}};
                    pp_hi_q <= {PW{1'b0}};
                end else if (pe_i) begin
                    one1_q  <= one_d;
                    two1_q  <= two_d;
                    neg1_q  <= neg_d;
                    en1_q   <= proc_i & en_s;
                    sg1_q   <= sign_i;
                    if (en1_q) begin
                        pp_lo_q <= pp_lo_d;
                        pp_hi_q <= pp_hi_d;
                    end else begin
                        pp_lo_q <= {PW{1'b0}};
                        pp_hi_q <= {PW{1'b0}};
                    end
                end
            end
        end
    endgenerate

    // ---------------------------------------------------------------- outputs
    generate
        for (c = 0; c < ACTIVE; c = c + 1) begin : g_out
            reg [DAC_BITS-1:0] dac_q;
            if (c < SLOTS - 1) begin : g_stage
                reg [DAC_BITS-1:0] stg_q;
                always @(posedge clk) begin
                    if (rst) begin
                        stg_q <= {DAC_BITS{1'b0}};
                        dac_q <= {DAC_BITS{1'b0}};
                    end else begin
                        if (stg_we_i[c]) stg_q <= res_w;
                        if (ce_i)        dac_q <= stg_q;
                    end
                end
            end else begin : g_last
                always @(posedge clk) begin
                    if (rst)       dac_q <= {DAC_BITS{1'b0}};
                    else if (ce_i) dac_q <= res_w;
                end
            end
            assign dac_o[c*DAC_BITS +: DAC_BITS] = dac_q;
        end
    endgenerate

    // Widths that would let -r overflow are a configuration error (see header).
    // synthesis translate_off
    initial begin
        if (SH < 0 || !(HALF < ((1 << (SINE_BITS - 1)) + (1 << AMP_BITS) - 1))) begin
            $display("fmt_dds_chan: DAC_BITS %0d invalid for SINE_BITS %0d AMP_BITS %0d",
                     DAC_BITS, SINE_BITS, AMP_BITS);
            $finish;
        end
        if (ACTIVE < 1 || ACTIVE > SLOTS) begin
            $display("fmt_dds_chan: ACTIVE %0d must be 1..SLOTS (%0d)", ACTIVE, SLOTS);
            $finish;
        end
    end
    // synthesis translate_on

endmodule

`default_nettype wire
