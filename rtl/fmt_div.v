// fmt_div -- pipelined unsigned divider, one result per clock.
//
// quot_o = floor(num_i / den_i) (low QW bits) and ovf_o = (num_i >= den_i * 2^QW),
// i.e. the quotient does not fit in QW bits (then quot_o is all ones).  den_i = 0
// always gives ovf_o = 1.
// Non-restoring long division with a narrow remainder: when the quotient fits, the
// numerator's high part num >> QW is below den, and every partial remainder r stays in
// [-den, den) (DEN_W + 1 bits, signed).  Stage s (s = 0..QW-1) appends numerator bit
// QW-1-s to r and subtracts den when r >= 0, adds it when r < 0 (one DEN_W + 2 bit
// adder/subtractor, no select after it); the quotient bit is 1 when the result is
// >= 0 (the same bits as restoring division) and is shifted into the register that held
// the numerator's low bits.  On overflow the stages work on a truncated remainder and
// the result is replaced by all ones.
// Latency: QW + 1 clock cycles from num_i/den_i/valid_i to quot_o/ovf_o/valid_o (one
// input register holding the overflow test, then one register per quotient bit).
// Twin: fmt.interp.div_fixed.
`default_nettype none
`include "fmt_defaults.vh"

module fmt_div #(
    parameter NUM_W = 32,   // dividend width (unsigned)
    parameter DEN_W = 24,   // divisor width (unsigned)
    parameter QW    = 9     // quotient bits (>= 2)
) (
    input  wire             clk,      // processing clock
    input  wire             rst,      // synchronous active-high reset (clears valid)
    input  wire             valid_i,  // input strobe (only travels with the data)
    input  wire [NUM_W-1:0] num_i,    // dividend
    input  wire [DEN_W-1:0] den_i,    // divisor
    output wire             valid_o,  // valid_i delayed by QW + 1 cycles
    output wire [QW-1:0]    quot_o,   // floor(num / den), all ones on overflow
    output wire             ovf_o     // quotient >= 2^QW (or den = 0)
);
    // numerator zero-extended to at least QW + 1 bits; its high part num >> QW and the
    // divisor compared at the common width CW
    localparam NE_W = (NUM_W > QW) ? NUM_W : QW + 1;
    localparam HI_W = NE_W - QW;
    localparam CW   = (HI_W > DEN_W) ? HI_W : DEN_W;

    reg [DEN_W-1:0] den_q [0:QW];
    reg [DEN_W:0]   rem_q [0:QW];             // partial remainder, signed, in [-den, den)
                                              // (unless overflow)
    reg [QW-1:0]    lq_q  [0:QW];             // numerator bits still to use (top) and
                                              // quotient bits decided so far (bottom)
    reg             ovf_q [0:QW];
    reg             vld_q [0:QW];

    // input stage: overflow test num >= den << QW, i.e. (num >> QW) >= den
    wire [NE_W-1:0] num_e = {{(NE_W-NUM_W){1'b0}}, num_i};
    wire [CW-1:0]   hi_c  = {{(CW-HI_W){1'b0}}, num_e[NE_W-1:QW]};
    wire [CW-1:0]   den_c = {{(CW-DEN_W){1'b0}}, den_i};
    always @(posedge clk) begin
        den_q[0] <= den_i;
        rem_q[0] <= {1'b0, hi_c[DEN_W-1:0]};
        lq_q[0]  <= num_e[QW-1:0];
        ovf_q[0] <= (hi_c >= den_c);
        if (rst) vld_q[0] <= 1'b0;
        else     vld_q[0] <= valid_i;
    end

    genvar s;
    generate
        for (s = 0; s < QW; s = s + 1) begin : g_stage
            // append the next numerator bit; r >= 0: subtract den, r < 0: add it
            wire             neg  = rem_q[s][DEN_W];
            wire [DEN_W+1:0] t    = {rem_q[s], lq_q[s][QW-1]};
            wire [DEN_W+1:0] dx   = {2'b00, den_q[s]} ^ {(DEN_W+2){!neg}};
            wire [DEN_W+1:0] d    = t + dx + {{(DEN_W+1){1'b0}}, !neg};
            wire             take = !d[DEN_W+1];
            always @(posedge clk) begin
                rem_q[s+1] <= d[DEN_W:0];
                lq_q[s+1]  <= {lq_q[s][QW-2:0], take};
                den_q[s+1] <= den_q[s];
                ovf_q[s+1] <= ovf_q[s];
                if (rst) vld_q[s+1] <= 1'b0;
                else     vld_q[s+1] <= vld_q[s];
            end
        end
    endgenerate

    assign valid_o = vld_q[QW];
    assign ovf_o   = ovf_q[QW];
    assign quot_o  = ovf_q[QW] ? {QW{1'b1}} : lq_q[QW];

`ifdef FORMAL
    // Formal properties (SymbiYosys, formal/fmt_div.sby; never seen by synthesis).
    // A shadow pipeline carries each input beside its stage and multiplies the
    // quotient bits decided so far by the divisor, by shift and add (f_prod): in stage s
    // the partial remainder, the numerator bits still to use and that product add up
    // to the numerator, and the (restoring) remainder stays in [0, den); at the output this
    // says quot * den <= num < (quot + 1) * den.  Overflow: ovf_o == (num >= den * 2^QW).
    localparam FW = NUM_W + QW + DEN_W + 1;          // no sum or shift can overflow
    reg f_past_q = 1'b0;
    always @(posedge clk) f_past_q <= 1'b1;
    always @(*) if (!f_past_q) assume (rst);
    genvar fs;
    generate
        for (fs = 0; fs <= QW; fs = fs + 1) begin : g_f
            reg [NUM_W-1:0] num_q;                   // the stage's input
            reg [FW-1:0]    prod_q;                  // its quotient bits so far x den, aligned
            reg             full_q = 1'b0;           // the stage holds a real input
            reg             f_vld;                   // its valid_i (reset clears)
            if (fs == 0) begin : g_in
                always @(posedge clk) begin
                    num_q  <= num_i;
                    prod_q <= {FW{1'b0}};
                    full_q <= 1'b1;
                    f_vld  <= rst ? 1'b0 : valid_i;
                end
            end else begin : g_step
                always @(posedge clk) begin
                    num_q  <= g_f[fs-1].num_q;
                    prod_q <= g_f[fs-1].prod_q
                              + (g_stage[fs-1].take ? ({{(FW-DEN_W){1'b0}}, den_q[fs-1]} << (QW - fs)) : {FW{1'b0}});
                    full_q <= g_f[fs-1].full_q;
                    f_vld  <= rst ? 1'b0 : g_f[fs-1].f_vld;
                end
            end
            wire [FW-1:0] n    = {{(FW-NUM_W){1'b0}}, num_q};
            wire [FW-1:0] d    = {{(FW-DEN_W){1'b0}}, den_q[fs]};
            // the restoring remainder: the signed partial remainder, plus den when < 0
            wire [FW-1:0] r_sx = {{(FW-DEN_W-1){rem_q[fs][DEN_W]}}, rem_q[fs]};
            wire [FW-1:0] r_re = rem_q[fs][DEN_W] ? r_sx + d : r_sx;
            // numerator bits not yet used, and the remainder, at their weight
            wire [FW-1:0] rest = (r_re << (QW - fs)) + (lq_q[fs] >> fs);
            always @(posedge clk) begin
                if (f_past_q && full_q) begin
                    assert (ovf_q[fs] == (n >= (d << QW)));
                    if (!ovf_q[fs]) assert (rest + prod_q == n && r_re < d);
                end
                if (f_past_q) assert (vld_q[fs] == f_vld);
                if (f_past_q && $past(rst)) assert (!vld_q[fs]);
            end
        end
    endgenerate
    always @(posedge clk) if (f_past_q && g_f[QW].full_q && ovf_o) assert (quot_o == {QW{1'b1}});
`endif
endmodule
`default_nettype wire
