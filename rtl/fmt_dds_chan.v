// fmt_dds_chan -- one DDS row: settings registers, phase accumulator, LUT-based
// amplitude scaling, rounding and PN bi-phase sign.  The sine table is outside
// (fmt_dds_rom2, shared by two rows): this block drives its address and takes the
// registered table word back.
//
// Sample k (k-th ce edge after reset; register values in effect before that edge):
//   edge k   : phase += tw (phase of sample k = sum of the tuning words of samples
//              0..k-1, modulo 2^PHASE_BITS, 0 after reset); the table reads
//              rom[phase >> (PHASE_BITS - TABLE_ADDR)]; amp, enable, tx_sign of
//              sample k are registered beside it.
//   edge k+1 : partial-product sums (see below).
//   edge k+2 : dac_o = enable ? (tx_sign ? -r : r) : 0.
// So the word of sample k is on dac_o after ce edge k+2 (3 registers, latency 3
// samples counted from the phase register).
//
// Amplitude product, LUT only (no DSP48E): p = s * amp with s the SINE_BITS-bit signed
// table word and amp the AMP_BITS-bit unsigned amplitude, formed as the shift-add of
// the partial products s << i for the set bits of amp, in two halves (low and high
// amplitude bits) registered at edge k+1 and added at edge k+2.  No `*` operator
// appears, so neither XST nor Yosys can map it to a DSP48E.
// Rounding: r = (p + 2^(SH-1)) >> SH, SH = SINE_BITS + AMP_BITS - DAC_BITS
// (round half up; the 2^(SH-1) is folded into the low half).  The sign is applied
// after rounding, so the words of +1 and -1 are exact negatives.
// Range: |s| <= 2^(SINE_BITS-1) - 1 and amp <= 2^AMP_BITS - 1 give
// |r| <= 2^(DAC_BITS-1) - 1 when 2^(SH-1) < 2^(SINE_BITS-1) + 2^AMP_BITS - 1 (always
// so for DAC_BITS > AMP_BITS), so -r never overflows: no saturation is needed.
// Full amplitude (2^AMP_BITS - 1) gives a peak of (2^AMP_BITS - 1) / 2^AMP_BITS of the
// DAC range (2040 of 2047 for 16/8/12 bits).
// Settings: a write (cfg_we_i = 1, any clk cycle, ce not needed) takes effect at the
// next clk edge.  While disabled the accumulator keeps running (phase continuity) and
// the output is 0.  Twin: sim/fmt/dds.py dds_bank_fixed.
`default_nettype none
`include "fmt_defaults.vh"

module fmt_dds_chan #(
    parameter PHASE_BITS = `FMT_PHASE_BITS,   // phase accumulator width
    parameter TABLE_ADDR = 10,                // sine table address bits (<= PHASE_BITS)
    parameter SINE_BITS  = `FMT_SINE_BITS,    // sine table word width (signed)
    parameter AMP_BITS   = `FMT_AMP_BITS,     // amplitude width (unsigned, >= 2)
    parameter DAC_BITS   = `FMT_DAC_BITS,     // output word width (signed), <= SINE_BITS + AMP_BITS
    parameter [PHASE_BITS-1:0] TW_RESET = 0   // tuning word after reset
) (
    input  wire                         clk,
    input  wire                         rst,         // synchronous, active high
    input  wire                         ce,          // sample strobe
    input  wire                         cfg_we_i,    // write one setting of this row
    input  wire [1:0]                   cfg_sel_i,   // 0 tuning word, 1 amplitude, 2 enable
    input  wire [PHASE_BITS-1:0]        cfg_data_i,  // value (LSB-aligned)
    input  wire                         tx_sign_i,   // PN sign of this sample, 1 = multiply by -1
    output wire [TABLE_ADDR-1:0]        addr_o,      // table address (registered phase, top bits)
    input  wire signed [SINE_BITS-1:0]  sine_i,      // table word of addr_o at the last ce edge
    output reg  signed [DAC_BITS-1:0]   dac_o        // output word, registered
);

    localparam PW   = SINE_BITS + AMP_BITS;         // product width (signed)
    localparam SH   = PW - DAC_BITS;                // rounding shift
    localparam SHM1 = (SH > 0) ? SH - 1 : 0;
    localparam [PW-1:0] HALF = (SH > 0) ? ({{(PW - 1){1'b0}}, 1'b1} << SHM1) : {PW{1'b0}};
    localparam LO_BITS = AMP_BITS / 2;              // amplitude bits summed in the low half

    // settings
    reg [PHASE_BITS-1:0] tw_q;
    reg [AMP_BITS-1:0]   amp_q;
    reg                  en_q;
    // datapath
    reg [PHASE_BITS-1:0] phase_q;
    reg [AMP_BITS-1:0]   amp1_q;
    reg                  en1_q, sg1_q, en2_q, sg2_q;
    reg signed [PW-1:0]  pp_lo_q, pp_hi_q;
    reg signed [PW-1:0]  pp_lo_d, pp_hi_d;

    assign addr_o = phase_q[PHASE_BITS-1 -: TABLE_ADDR];

    wire signed [PW-1:0] s_ext = {{AMP_BITS{sine_i[SINE_BITS-1]}}, sine_i};

    integer i;
    always @* begin
        pp_lo_d = HALF;
        pp_hi_d = {PW{1'b0}};
        for (i = 0; i < AMP_BITS; i = i + 1) begin
            if (amp1_q[i]) begin
                if (i < LO_BITS) pp_lo_d = pp_lo_d + (s_ext <<< i);
                else             pp_hi_d = pp_hi_d + (s_ext <<< i);
            end
        end
    end

    // the low SH bits of the sum are the fraction that the rounding drops
    /* verilator lint_off UNUSEDSIGNAL */
    wire signed [PW-1:0]       sum_w = pp_lo_q + pp_hi_q;
    /* verilator lint_on UNUSEDSIGNAL */
    wire signed [DAC_BITS-1:0] r_w   = sum_w[PW-1:SH];

    always @(posedge clk) begin
        if (rst) begin
            tw_q    <= TW_RESET;
            amp_q   <= {AMP_BITS{1'b1}};
            en_q    <= 1'b1;
            phase_q <= {PHASE_BITS{1'b0}};
            amp1_q  <= {AMP_BITS{1'b0}};
            en1_q   <= 1'b0;
            sg1_q   <= 1'b0;
            en2_q   <= 1'b0;
            sg2_q   <= 1'b0;
            pp_lo_q <= {PW{1'b0}};
            pp_hi_q <= {PW{1'b0}};
            dac_o   <= {DAC_BITS{1'b0}};
        end else begin
            if (cfg_we_i) begin
                case (cfg_sel_i)
                    2'd0:    tw_q  <= cfg_data_i;
                    2'd1:    amp_q <= cfg_data_i[AMP_BITS-1:0];
                    2'd2:    en_q  <= cfg_data_i[0];
                    default: ;
                endcase
            end
            if (ce) begin
                phase_q <= phase_q + tw_q;
                amp1_q  <= amp_q;
                en1_q   <= en_q;
                sg1_q   <= tx_sign_i;
                pp_lo_q <= pp_lo_d;
                pp_hi_q <= pp_hi_d;
                en2_q   <= en1_q;
                sg2_q   <= sg1_q;
                dac_o   <= !en2_q ? {DAC_BITS{1'b0}} : (sg2_q ? -r_w : r_w);
            end
        end
    end

    // Widths that would let -r overflow are a configuration error (see header).
    // synthesis translate_off
    initial begin
        if (SH < 0 || !(HALF < ((1 << (SINE_BITS - 1)) + (1 << AMP_BITS) - 1))) begin
            $display("fmt_dds_chan: DAC_BITS %0d invalid for SINE_BITS %0d AMP_BITS %0d",
                     DAC_BITS, SINE_BITS, AMP_BITS);
            $finish;
        end
    end
    // synthesis translate_on

endmodule

`default_nettype wire
