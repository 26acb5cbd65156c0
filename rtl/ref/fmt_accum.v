// Reference only: not instantiated by fmt_core; kept as the documented, tested reference of
// the frame accumulation for M = 2^m (exact sum, round half up, saturation: rx_fixed.accum_fixed,
// tb/fmt_accum), which fmt_rx_array's shared accumulator extends to any M.
// fmt_accum -- accumulates per-cell signal strengths over the M windows of a frame
// and scales the sum to HM_W-bit unsigned heat-map cells, saturating.
//
// One beat = one row (cell) of LANES columns (D_W-bit unsigned magnitudes each); each
// row comes once per window.  M = 2^m_log2 windows per frame (run-time, carried per beat
// as in_shift_i = m_log2 so a change never splits a frame); in_first_i / in_last_i mark the
// first and last window of the frame (both 1 when M = 1).
//   sum   = in_first_i ? mag : mem[row] + mag         (SUM_W = D_W + M_LOG2_MAX bits, exact)
//   cell  = (sum + 2^(s-1)) >> s,  s = in_shift_i + HM_SHIFT (round half up; s = 0: sum)
//   out   = min(cell, 2^HM_W - 1), sat_o sticky when the min clips
// HM_SHIFT includes the factor 2 of fmt_pair_split (HM_SHIFT = 1: cell = |A| in FFT
// output LSBs, averaged over M).  Per-cell storage: ROWS x LANES*SUM_W bits, an
// inferred distributed RAM (read asynchronously, written at the beat).
// Latency: 2 ce cycles from the beat to out_valid_o (only for in_last_i beats).
// Twin: sim/fmt/rx_array.py accum_fixed.
`default_nettype none
`include "fmt_defaults.vh"

module fmt_accum #(
    parameter ROWS       = `FMT_ROWS,    // cells per lane (rows)
    parameter LANES      = 2,            // columns handled side by side
    parameter D_W        = 19,           // input magnitude width (unsigned)
    parameter M_LOG2_MAX = 3,            // largest log2 M (M <= 2^M_LOG2_MAX)
    parameter HM_W       = `FMT_HM_W,    // heat-map cell width (unsigned)
    parameter HM_SHIFT   = 1,            // fixed right shift of the sum (1 = undo the 2 of pair split)
    parameter ROW_W      = (ROWS > 1) ? $clog2(ROWS) : 1,   // row index width
    parameter SH_W       = (M_LOG2_MAX > 0) ? $clog2(M_LOG2_MAX + 1) : 1  // width of in_shift_i
) (
    input  wire                    clk,
    input  wire                    rst,        // synchronous, active high (clears flag, valid)
    input  wire                    ce,         // sample strobe
    input  wire                    in_valid_i, // one row of magnitudes this ce cycle
    input  wire [ROW_W-1:0]        in_row_i,   // row index
    input  wire [LANES*D_W-1:0]    in_data_i,  // lane l at [l*D_W +: D_W]
    input  wire                    in_first_i, // first window of the frame (restart the sum)
    input  wire                    in_last_i,  // last window of the frame (emit the cell)
    input  wire [SH_W-1:0]         in_shift_i, // log2 M of this frame (0..M_LOG2_MAX)
    output reg                     out_valid_o, // one row of heat-map cells this ce cycle
    output reg  [ROW_W-1:0]        out_row_o,  // its row index
    output reg  [LANES*HM_W-1:0]   out_data_o, // lane l at [l*HM_W +: HM_W], unsigned
    output reg                     sat_o       // sticky: a cell saturated at 2^HM_W - 1
);

    localparam SUM_W = D_W + M_LOG2_MAX;
    localparam TS    = M_LOG2_MAX + HM_SHIFT;          // largest total shift
    localparam EW    = (SUM_W > HM_W) ? SUM_W + 1 : HM_W + 1;  // width after adding the rounding half

    reg [LANES*SUM_W-1:0] mem [0:ROWS-1];
    wire [LANES*SUM_W-1:0] rd = mem[in_row_i];

    reg [LANES*SUM_W-1:0] sum_q;
    reg                   sv_q;
    reg [ROW_W-1:0]       srow_q;
    reg [SH_W-1:0]        ssh_q;

    // stage 1: accumulate
    reg [LANES*SUM_W-1:0] sum_d;
    integer l;
    always @* begin
        for (l = 0; l < LANES; l = l + 1) begin
            sum_d[l*SUM_W +: SUM_W] = (in_first_i ? {SUM_W{1'b0}} : rd[l*SUM_W +: SUM_W])
                                    + {{M_LOG2_MAX{1'b0}}, in_data_i[l*D_W +: D_W]};
        end
    end

    always @(posedge clk) begin
        if (ce && in_valid_i) begin
            mem[in_row_i] <= sum_d;
        end
    end

    always @(posedge clk) begin
        if (rst) begin
            sv_q <= 1'b0;
        end else if (ce) begin
            sv_q <= in_valid_i && in_last_i;
        end
    end

    always @(posedge clk) begin
        if (ce) begin
            sum_q  <= sum_d;
            srow_q <= in_row_i;
            ssh_q  <= in_shift_i;
        end
    end

    // stage 2: round, shift, saturate
    wire [TS:0] shift_tot = {{(TS+1-SH_W){1'b0}}, ssh_q} + HM_SHIFT;
    reg [LANES*HM_W-1:0] cell_d;
    reg                  clip_d;
    reg [EW-1:0]         rnd;
    reg [EW-1:0]         scaled;
    always @* begin
        clip_d = 1'b0;
        for (l = 0; l < LANES; l = l + 1) begin
            rnd    = {{(EW-SUM_W){1'b0}}, sum_q[l*SUM_W +: SUM_W]} + ({{(EW-1){1'b0}}, 1'b1} << shift_tot >> 1);
            scaled = rnd >> shift_tot;
            if (scaled > {{(EW-HM_W){1'b0}}, {HM_W{1'b1}}}) begin
                cell_d[l*HM_W +: HM_W] = {HM_W{1'b1}};
                clip_d = 1'b1;
            end else begin
                cell_d[l*HM_W +: HM_W] = scaled[HM_W-1:0];
            end
        end
    end

    always @(posedge clk) begin
        if (rst) begin
            out_valid_o <= 1'b0;
            sat_o       <= 1'b0;
        end else if (ce) begin
            out_valid_o <= sv_q;
            if (sv_q && clip_d) sat_o <= 1'b1;
        end
    end

    always @(posedge clk) begin
        if (ce) begin
            out_row_o  <= srow_q;
            out_data_o <= cell_d;
        end
    end

endmodule

`default_nettype wire
