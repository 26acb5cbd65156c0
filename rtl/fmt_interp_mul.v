// fmt_interp_mul -- pipelined signed product p_o = a_i * b_i (exact, PW bits), written
// in the form that maps onto 18 x 18 multipliers with their registers.
//
// An operand wider than 18 bits is split into a 17-bit unsigned low part and a signed
// high part (x = x_hi * 2^17 + x_lo, so AW, BW <= 35); each of the (up to) four partial
// products is at most 18 x 18 bits signed (one DSP48E or one ECP5 MULT18X18D) and is
// registered straight at the multiplier output (the M register); the next stage adds the
// partial products shifted by 17 / 34 bits (the cascade adder) into the P register.
// Operands come from the caller's flip-flops (the multipliers' A/B registers), which
// must be fed by a computed value, not by a plain delay line (Yosys would merge that into SRLs).
// Latency: 2 clock cycles (M, P).  Twin: the products of fmt.interp.interp_fixed.
`default_nettype none
`include "fmt_defaults.vh"

module fmt_interp_mul #(
    parameter AW = 20,          // width of a_i (signed), 2 .. 35
    parameter BW = 20,          // width of b_i (signed), 2 .. 35
    parameter PW = AW + BW      // width of p_o (the product must fit)
) (
    input  wire                 clk,  // processing clock
    input  wire signed [AW-1:0] a_i,  // operand (registered by the caller)
    input  wire signed [BW-1:0] b_i,  // operand (registered by the caller)
    output reg  signed [PW-1:0] p_o   // a_i * b_i, 2 cycles later
);
    // 18-bit signed chunks: (hi, lo) = (0, a) when a fits 18 bits
    wire signed [17:0] a_lo, a_hi, b_lo, b_hi;
    generate
        if (AW > 18) begin : g_a2
            assign a_lo = {1'b0, a_i[16:0]};
            assign a_hi = {{(35-AW){a_i[AW-1]}}, a_i[AW-1:17]};
        end else begin : g_a1
            assign a_lo = {{(18-AW){a_i[AW-1]}}, a_i};
            assign a_hi = 18'sd0;
        end
        if (BW > 18) begin : g_b2
            assign b_lo = {1'b0, b_i[16:0]};
            assign b_hi = {{(35-BW){b_i[BW-1]}}, b_i[BW-1:17]};
        end else begin : g_b1
            assign b_lo = {{(18-BW){b_i[BW-1]}}, b_i};
            assign b_hi = 18'sd0;
        end
    endgenerate

    // M: the partial products, each registered at its multiplier
    reg signed [35:0] m_ll_q, m_lh_q, m_hl_q, m_hh_q;
    always @(posedge clk) begin
        m_ll_q <= a_lo * b_lo;
        m_lh_q <= a_lo * b_hi;
        m_hl_q <= a_hi * b_lo;
        m_hh_q <= a_hi * b_hi;
    end

    // P: the 17-bit-shifted sum; the low 17 bits are those of m_ll (the other partial
    // products are multiples of 2^17), the upper HW bits are summed modulo 2^HW
    localparam HW = PW - 17;
    localparam XW = HW + 53;            // wide enough for every term, then cut to HW
    /* verilator lint_off UNUSEDSIGNAL */ // bits above HW: beyond the product's width
    wire [XW-1:0] ll = {{(XW-19){m_ll_q[35]}}, m_ll_q[35:17]};
    wire [XW-1:0] lh = {{(XW-36){m_lh_q[35]}}, m_lh_q};
    wire [XW-1:0] hl = {{(XW-36){m_hl_q[35]}}, m_hl_q};
    wire [XW-1:0] hh = {{(XW-53){m_hh_q[35]}}, m_hh_q, 17'd0};
    /* verilator lint_on UNUSEDSIGNAL */
    always @(posedge clk) p_o <= {ll[HW-1:0] + lh[HW-1:0] + hl[HW-1:0] + hh[HW-1:0], m_ll_q[16:0]};
endmodule
`default_nettype wire
