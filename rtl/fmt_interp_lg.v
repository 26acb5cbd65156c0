// fmt_interp_lg -- pipelined base-2 logarithm of an unsigned integer (x > 0).
//
// lg_o = n * 2^12 + LOG_ROM[m] = {n, LOG_ROM[m]}, n = floor(log2 x) (position of the
// leading one), m = the 8 bits after the leading one (x is left-aligned first, so for
// n < 8 the missing bits are zeros), LOG_ROM[m] = round(4096 * log2(1 + (m + 0.5)/256))
// (12 fractional bits, < 4096).  Error |lg_o/4096 - log2 x| <= 0.0028 + 1/8192.
// x = 0 gives n = 0 and an undefined fraction (callers check x > 0).
// ROM rtl/fmt_interp_log.hex (256 x 12 bit) is written by `python -m fmt.interp
// --write-hex`.  Latency: 2 clock cycles.  Twin: fmt.interp.lg_fixed.
`default_nettype none
`include "fmt_defaults.vh"

module fmt_interp_lg #(
    parameter X_W = 48                  // input width (>= 9)
) (
    input  wire                      clk,  // processing clock
    input  wire [X_W-1:0]            x_i,  // argument (unsigned, > 0)
    output wire [$clog2(X_W)+11:0]   lg_o  // log2(x) with 12 fractional bits, 2 cycles later
);
    localparam NB = $clog2(X_W);

    reg [11:0] rom [0:255];
    initial begin
`ifdef FMT_ROM_DIR
        $readmemh({`FMT_ROM_DIR, "fmt_interp_log.hex"}, rom);
`else
        $readmemh("fmt_interp_log.hex", rom);
`endif
    end

    // leading-one position (priority encoder)
    reg [NB-1:0] n_d;
    integer i;
    always @(*) begin
        n_d = {NB{1'b0}};
        for (i = 0; i < X_W; i = i + 1)
            if (x_i[i]) n_d = i[NB-1:0];
    end
    // left-align: the leading one moves to bit X_W-1; the next 8 bits address the ROM
    /* verilator lint_off UNUSEDSIGNAL */ // only the 8 bits after the leading one are used
    wire [X_W-1:0] xn = x_i << (X_W - 1 - n_d);
    /* verilator lint_on UNUSEDSIGNAL */

    reg [NB-1:0] n_q, n2_q;
    reg [7:0]    m_q;
    reg [11:0]   f_q;
    always @(posedge clk) begin
        n_q  <= n_d;
        m_q  <= xn[X_W-2 -: 8];
        n2_q <= n_q;
        f_q  <= rom[m_q];
    end
    assign lg_o = {n2_q, f_q};
endmodule
`default_nettype wire
