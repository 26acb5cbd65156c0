// fmt_flatten -- field flattening of the heat-map stream: z' = (z - offset) * gain.
//
// One heat-map row per beat (docs/ARCHITECTURE.md heat-map stream), all COLS columns
// in parallel (COLS multipliers), a beat may come on every cycle.  Output is the same
// stream format, delayed by exactly LATENCY = 5 cycles (valid, row, frame, data, eof
// all delayed alike):
//   s1: offset/gain RAM read (synchronous, address = row), input registered
//   s2: RAM output register (the block RAM's own), input delayed
//   s3: d = z - offset, clamped at 0 (a cell below its baseline is noise, not flagged)
//   s4: p = d * gain                          (HM_W + 16 bits, one DSP48E per column,
//       operands and product registered)
//   s5: q = (p + 2^13) >> 14 (round half up); q > 2^HM_W - 1 -> 2^HM_W - 1, flagged
// Formats: z, offset, z' unsigned HM_W bits; gain unsigned 16-bit Q2.14 (1.0 = 16384).
// Bit-exact twin: sim/fmt/flatten.py flatten_fixed().
//
// Calibration memory: per cell offset and gain in inferred RAM, one memory per column
// (ROWS words of {gain 16, offset HM_W} bits, the halves written separately; block RAM
// with CAL_BRAM = 1: one RAMB18 (512 x 36 simple dual port) per column at the default
// size, ~960 LUT6 of RAM32M with CAL_BRAM = 0); written one cell at a time through
// cal_we_i / cal_sel_i / cal_row_i / cal_col_i / cal_data_i.  Writes take effect at
// frame boundaries: a frame is flattened with one calibration.  A write that comes
// while a frame arrives (from its first row beat to its hm_eof) waits in a queue of
// CAL_Q words (LUT RAM) and is written to the column memories after the frame's hm_eof,
// one per cycle without a row beat (the hm_eof cycle counts); a write between frames
// is written at once.  The column memories are read-first: a write is seen by the
// beats of the following cycles.  A write that finds the queue full writes the
// queue's oldest word at once, inside the frame, and sets cal_late_o (sticky, cleared
// by rst): at most CAL_Q writes may come during one frame's rows (the core's control
// port writes one cell per ~10^5 cycles).  The read-back copy (below) takes every
// write at once.  Power-on / reset does NOT
// clear the RAM (block RAM has no reset); after configuration load offset 0 / gain
// 16384 (identity) or a calibration: with INIT_IDENTITY = 1 (default) the memories are
// initialised to the identity for simulation and FPGA configuration.
// Read-back: cal_re_i latches (row, col, sel); the read is served in the first cycle
// without a heat-map beat, cal_rvalid_o/cal_rdata_o follow 2 cycles later (a new
// request before the answer replaces the pending one).  It reads a shadow copy of the
// calibration (one memory of 2^(1+ROW_IDX_W+COL_IDX_W) CAL_W-bit words, address
// {sel, row, col}, written with the column memories, read-first; block RAM at the
// default size) instead of a COLS:1 multiplexer over the column memories' read
// registers: 2 RAMB36 at 30 x 40 instead of ~510 LUT6.
// Saturation: sat_flag_o is sticky (cleared by rst or sat_clr_i), one cycle behind the
// output beat; sat_count_o counts saturated cells (saturating counter), three cycles
// behind the output beat (population count in two registered stages: groups of 16
// cells, then their sum; sat_clr_i also clears the counts in flight).
`default_nettype none
`include "fmt_defaults.vh"

module fmt_flatten #(
    parameter ROWS          = `FMT_ROWS,         // heat-map rows
    parameter COLS          = `FMT_COLS,         // heat-map columns (cells per beat)
    parameter HM_W          = `FMT_HM_W,         // cell width, unsigned
    parameter FRAME_W       = 16,                // frame number width
    parameter CNT_W         = 16,                // saturation counter width
    parameter INIT_IDENTITY = 1,                 // 1: memories start at offset 0, gain 1.0
    parameter CAL_BRAM      = 1,                 // column calibration memories: 1 block RAM, 0 LUT RAM
    parameter CAL_Q         = 16,                // calibration writes held during a frame (power of 2, >= 2)
    parameter ROW_IDX_W     = (ROWS > 1) ? $clog2(ROWS) : 1,  // row index width
    parameter COL_IDX_W     = (COLS > 1) ? $clog2(COLS) : 1,  // column index width
    parameter CAL_W         = (HM_W > 16) ? HM_W : 16         // calibration data width
) (
    input  wire                    clk,
    input  wire                    rst,          // synchronous, active high
    // heat-map stream in
    input  wire                    hm_valid_i,   // one row this cycle
    input  wire [ROW_IDX_W-1:0]    hm_row_i,     // row index
    input  wire [FRAME_W-1:0]      hm_frame_i,   // frame number
    input  wire [COLS*HM_W-1:0]    hm_data_i,    // column c at [c*HM_W +: HM_W]
    input  wire                    hm_eof_i,     // end of frame marker
    // heat-map stream out (LATENCY = 5 cycles)
    output reg                     hm_valid_o,   // flattened row
    output reg  [ROW_IDX_W-1:0]    hm_row_o,     // row index
    output reg  [FRAME_W-1:0]      hm_frame_o,   // frame number
    output reg  [COLS*HM_W-1:0]    hm_data_o,    // flattened cells
    output reg  [COLS-1:0]         hm_sat_o,     // per column: this cell saturated
    output reg                     hm_eof_o,     // end of frame marker
    // calibration write port
    input  wire                    cal_we_i,     // write one cell's offset or gain
    input  wire                    cal_sel_i,    // 0 = offset (HM_W bits), 1 = gain (Q2.14)
    input  wire [ROW_IDX_W-1:0]    cal_row_i,    // cell row
    input  wire [COL_IDX_W-1:0]    cal_col_i,    // cell column
    input  wire [CAL_W-1:0]        cal_data_i,   // value (offset: low HM_W bits, gain: low 16 bits)
    input  wire                    cal_re_i,     // read back cal_row_i/cal_col_i/cal_sel_i
    output reg                     cal_rvalid_o, // read-back data valid (one cycle)
    output reg  [CAL_W-1:0]        cal_rdata_o,  // read-back value (zero-extended)
    output reg                     cal_late_o,   // sticky: a write was applied inside a frame (queue full)
    // saturation monitor
    input  wire                    sat_clr_i,    // clear flag and counter
    output reg                     sat_flag_o,   // sticky: some cell saturated
    output reg  [CNT_W-1:0]        sat_count_o   // saturated cells (stops at all ones)
);

    localparam GAIN_W = 16;
    localparam GAIN_FRAC = 14;
    localparam P_W = HM_W + GAIN_W;
    localparam [P_W-1:0] HALF = {{(P_W-1){1'b0}}, 1'b1} << (GAIN_FRAC - 1);
    localparam POP_W = $clog2(COLS + 1);
    localparam PG    = 16;                                  // cells per population-count group
    localparam NG    = (COLS + PG - 1) / PG;                // groups
    localparam PGW   = 5;                                   // count of one group (0 .. 16)
    localparam PSW   = (POP_W > PGW) ? POP_W : PGW;         // count of a beat

    // ---- pipeline control -----------------------------------------------------------
    reg                   v1_q, v2_q, v3_q, v4_q;
    reg                   e1_q, e2_q, e3_q, e4_q;
    reg [ROW_IDX_W-1:0]   r1_q, r2_q, r3_q, r4_q;
    reg [FRAME_W-1:0]     f1_q, f2_q, f3_q, f4_q;
    reg [COLS*HM_W-1:0]   z1_q, z2_q;
    reg [COLS*HM_W-1:0]   d3_q;
    reg [COLS*GAIN_W-1:0] g3_q;
    reg [COLS*P_W-1:0]    p4_q;
    wire [COLS*HM_W-1:0]  q5;
    wire [COLS-1:0]       sat5;

    // read-back request, served in a cycle without a heat-map beat
    reg                  rd_pend_q, rd_go_q, rd_sel_q;
    reg [ROW_IDX_W-1:0]  rd_row_q;
    reg [COL_IDX_W-1:0]  rd_col_q;
    wire                 rd_serve = rd_pend_q && !hm_valid_i;
    wire [ROW_IDX_W-1:0] rd_addr  = hm_row_i;   // column memories: heat-map beats only

    // synthesis translate_off
    initial begin
        if (CAL_Q < 2 || (CAL_Q & (CAL_Q - 1)) != 0) begin
            $display("fmt_flatten: CAL_Q %0d must be a power of two >= 2", CAL_Q);
            $finish;
        end
    end
    // synthesis translate_on

    // ---- calibration writes at frame boundaries -------------------------------------------
    localparam QA = (CAL_Q > 1) ? $clog2(CAL_Q) : 1;         // queue address width
    localparam QW = 1 + ROW_IDX_W + COL_IDX_W + CAL_W;       // {sel, row, col, data}
    (* ram_style = "distributed" *)
    reg  [QW-1:0]        cq_mem [0:CAL_Q-1];
    reg  [QA-1:0]        cq_wp_q, cq_rp_q;
    reg  [QA:0]          cq_n_q;                             // words queued
    reg                  in_q;                               // a frame is arriving
    wire                 cq_empty = (cq_n_q == {(QA+1){1'b0}});
    wire                 cq_full  = (cq_n_q[QA] == 1'b1);    // == CAL_Q
    // no frame's rows can be read in this cycle's column-memory write: between frames,
    // or the hm_eof cycle (the frame's rows are in; the next frame's come later)
    wire                 cal_idle = !hm_valid_i && (!in_q || hm_eof_i);
    wire                 cq_pop   = !cq_empty && (cal_idle || (cal_we_i && cq_full));
    wire                 cw_now   = cal_we_i && cal_idle && cq_empty;   // written at once
    wire                 cq_push  = cal_we_i && !cw_now;
    wire [QW-1:0]        cq_head  = cq_mem[cq_rp_q];
    // the column memories' write of this cycle: the queue's oldest word, else the input
    wire                 cw_v     = cq_pop || cw_now;
    wire                 cw_sel   = cq_pop ? cq_head[QW-1] : cal_sel_i;
    wire [ROW_IDX_W-1:0] cw_row   = cq_pop ? cq_head[QW-2 -: ROW_IDX_W] : cal_row_i;
    wire [COL_IDX_W-1:0] cw_col   = cq_pop ? cq_head[CAL_W +: COL_IDX_W] : cal_col_i;
    wire [CAL_W-1:0]     cw_data  = cq_pop ? cq_head[CAL_W-1:0] : cal_data_i;
    always @(posedge clk) begin
        if (cq_push) cq_mem[cq_wp_q] <= {cal_sel_i, cal_row_i, cal_col_i, cal_data_i};
    end
    always @(posedge clk) begin
        if (rst) begin
            cq_wp_q    <= {QA{1'b0}};
            cq_rp_q    <= {QA{1'b0}};
            cq_n_q     <= {(QA+1){1'b0}};
            in_q       <= 1'b0;
            cal_late_o <= 1'b0;
        end else begin
            if (hm_eof_i)        in_q <= 1'b0;
            else if (hm_valid_i) in_q <= 1'b1;
            if (cq_push) cq_wp_q <= cq_wp_q + 1'b1;
            if (cq_pop)  cq_rp_q <= cq_rp_q + 1'b1;
            if (cq_push && !cq_pop)      cq_n_q <= cq_n_q + 1'b1;
            else if (cq_pop && !cq_push) cq_n_q <= cq_n_q - 1'b1;
            if (cq_pop && !cal_idle) cal_late_o <= 1'b1;      // full: written inside a frame
        end
    end

    genvar c;
    generate
        for (c = 0; c < COLS; c = c + 1) begin : g_col
            // {gain, offset} of this column's cells; read-first (a write is seen by the
            // beats of the following cycles); no reset (block RAM has none)
            wire [HM_W+GAIN_W-1:0] cal_rd;           // read register (s1)
            reg  [HM_W+GAIN_W-1:0] cal_rd2_q;        // output register (s2)
            wire [HM_W-1:0]   off_rd_q  = cal_rd2_q[HM_W-1:0];
            wire [GAIN_W-1:0] gain_rd_q = cal_rd2_q[HM_W +: GAIN_W];
            wire we_off  = cw_v && (cw_col == c) && !cw_sel;
            wire we_gain = cw_v && (cw_col == c) &&  cw_sel;
            // The two branches below are the same memory and differ only in the
            // ram_style attribute: XST and Yosys read the attribute as a literal string,
            // so it cannot come from a parameter, and one copy per style is the portable
            // way to choose (CAL_BRAM).  Change both together.
            if (CAL_BRAM != 0) begin : g_bram
                (* ram_style = "block" *)
                reg [HM_W+GAIN_W-1:0] mem [0:ROWS-1];
                reg [HM_W+GAIN_W-1:0] rd_q;
                integer i;
                initial begin
                    for (i = 0; i < ROWS; i = i + 1)
                        mem[i] = {((INIT_IDENTITY != 0) ? (16'd1 << GAIN_FRAC) : 16'd0), {HM_W{1'b0}}};
                end
                always @(posedge clk) begin
                    if (we_off)  mem[cw_row][HM_W-1:0]      <= cw_data[HM_W-1:0];
                    if (we_gain) mem[cw_row][HM_W +: GAIN_W] <= cw_data[GAIN_W-1:0];
                    rd_q <= mem[rd_addr];
                end
                assign cal_rd = rd_q;
            end else begin : g_lutram
                (* ram_style = "distributed" *)
                reg [HM_W+GAIN_W-1:0] mem [0:ROWS-1];
                reg [HM_W+GAIN_W-1:0] rd_q;
                integer i;
                initial begin
                    for (i = 0; i < ROWS; i = i + 1)
                        mem[i] = {((INIT_IDENTITY != 0) ? (16'd1 << GAIN_FRAC) : 16'd0), {HM_W{1'b0}}};
                end
                always @(posedge clk) begin
                    if (we_off)  mem[cw_row][HM_W-1:0]      <= cw_data[HM_W-1:0];
                    if (we_gain) mem[cw_row][HM_W +: GAIN_W] <= cw_data[GAIN_W-1:0];
                    rd_q <= mem[rd_addr];
                end
                assign cal_rd = rd_q;
            end

            // s3: subtract, clamp at zero
            wire [HM_W:0] diff = {1'b0, z2_q[c*HM_W +: HM_W]} - {1'b0, off_rd_q};
            always @(posedge clk) begin
                cal_rd2_q <= cal_rd;
                d3_q[c*HM_W +: HM_W]     <= diff[HM_W] ? {HM_W{1'b0}} : diff[HM_W-1:0];
                g3_q[c*GAIN_W +: GAIN_W] <= gain_rd_q;
                // s4: multiply
                p4_q[c*P_W +: P_W] <= d3_q[c*HM_W +: HM_W] * g3_q[c*GAIN_W +: GAIN_W];
            end
            // s5: round half up, saturate (p + HALF cannot overflow P_W: p <= (2^HM_W-1)(2^16-1))
            /* verilator lint_off UNUSEDSIGNAL */ // the 14 fraction bits are dropped by the rounding
            wire [P_W-1:0] rnd = p4_q[c*P_W +: P_W] + HALF;
            /* verilator lint_on UNUSEDSIGNAL */
            wire [P_W-GAIN_FRAC-1:0] qfull = rnd[P_W-1:GAIN_FRAC];
            assign sat5[c] = |qfull[P_W-GAIN_FRAC-1:HM_W];
            assign q5[c*HM_W +: HM_W] = sat5[c] ? {HM_W{1'b1}} : qfull[HM_W-1:0];
        end
    endgenerate

    // population count of the saturated cells of the output beat: stage 1 counts each
    // group of 16 cells (4-cell counts in LUTs, then two levels of small adders), stage
    // 2 adds the group counts, then the counter adds the total
    function [2:0] pop4;
        input [3:0] b;
        reg s01, s23, c01, c23, k;
        begin
            s01 = b[0] ^ b[1];  c01 = b[0] & b[1];
            s23 = b[2] ^ b[3];  c23 = b[2] & b[3];
            k   = s01 & s23;
            pop4 = {(c01 & c23) | ((c01 ^ c23) & k), c01 ^ c23 ^ k, s01 ^ s23};
        end
    endfunction

    reg  [NG*PG-1:0]  sat_pad;                  // hm_sat_o, zero-padded to NG groups
    reg  [NG*PSW-1:0] pg_q;                     // group counts (stage 1)
    reg  [PSW-1:0]    pop_q;                    // beat count (stage 2)
    reg  [NG*PSW-1:0] pg_d;
    reg  [PSW-1:0]    pop_d;
    integer k;
    always @(*) begin
        sat_pad = {(NG*PG){1'b0}};
        sat_pad[COLS-1:0] = hm_sat_o;
        for (k = 0; k < NG; k = k + 1)
            pg_d[k*PSW +: PSW] = ({{(PSW-3){1'b0}}, pop4(sat_pad[k*PG      +: 4])} +
                                  {{(PSW-3){1'b0}}, pop4(sat_pad[k*PG +  4 +: 4])}) +
                                 ({{(PSW-3){1'b0}}, pop4(sat_pad[k*PG +  8 +: 4])} +
                                  {{(PSW-3){1'b0}}, pop4(sat_pad[k*PG + 12 +: 4])});
        pop_d = {PSW{1'b0}};
        for (k = 0; k < NG; k = k + 1)
            pop_d = pop_d + pg_q[k*PSW +: PSW];
    end
    wire [CNT_W:0] cnt_sum = {1'b0, sat_count_o} + {{(CNT_W+1-PSW){1'b0}}, pop_q};

    // read-back: shadow copy of the calibration, address {sel, row, col}, holding the
    // word as it is read back (offset: low HM_W bits, gain: low 16 bits, zero-extended)
    localparam SH_AW = 1 + ROW_IDX_W + COL_IDX_W;
    reg  [CAL_W-1:0] shadow_mem [0:(1 << SH_AW)-1];
    reg  [CAL_W-1:0] rd_word_q;                 // shadow read register (serve cycle + 1)
    reg  [CAL_W-1:0] sh_wdata;
    integer j;
    initial begin
        for (j = 0; j < (1 << SH_AW); j = j + 1)
            shadow_mem[j] = ((INIT_IDENTITY != 0) && (j >= (1 << (SH_AW - 1))))
                            ? (16'd1 << GAIN_FRAC) : {CAL_W{1'b0}};
    end
    always @(*) begin
        sh_wdata = {CAL_W{1'b0}};
        if (cal_sel_i) sh_wdata[GAIN_W-1:0] = cal_data_i[GAIN_W-1:0];
        else           sh_wdata[HM_W-1:0]   = cal_data_i[HM_W-1:0];
    end
    always @(posedge clk) begin
        if (cal_we_i) shadow_mem[{cal_sel_i, cal_row_i, cal_col_i}] <= sh_wdata;
        rd_word_q <= shadow_mem[{rd_sel_q, rd_row_q, rd_col_q}];
    end
    always @(posedge clk) begin
        if (rst) begin
            rd_pend_q    <= 1'b0;
            rd_go_q      <= 1'b0;
            rd_row_q     <= {ROW_IDX_W{1'b0}};
            rd_col_q     <= {COL_IDX_W{1'b0}};
            rd_sel_q     <= 1'b0;
            cal_rvalid_o <= 1'b0;
        end else begin
            if (cal_re_i) begin
                rd_pend_q <= 1'b1;
                rd_row_q  <= cal_row_i;
                rd_col_q  <= cal_col_i;
                rd_sel_q  <= cal_sel_i;
            end else if (rd_serve) begin
                rd_pend_q <= 1'b0;
            end
            rd_go_q      <= rd_serve && !cal_re_i;
            cal_rvalid_o <= rd_go_q;
        end
        cal_rdata_o <= rd_word_q;
    end

    always @(posedge clk) begin
        z1_q <= hm_data_i;  z2_q <= z1_q;
        r1_q <= hm_row_i;   f1_q <= hm_frame_i;
        r2_q <= r1_q;       f2_q <= f1_q;
        r3_q <= r2_q;       f3_q <= f2_q;
        r4_q <= r3_q;       f4_q <= f3_q;
        hm_row_o   <= r4_q;
        hm_frame_o <= f4_q;
        hm_data_o  <= q5;
        if (rst) begin
            v1_q <= 1'b0; v2_q <= 1'b0; v3_q <= 1'b0; v4_q <= 1'b0; hm_valid_o <= 1'b0;
            e1_q <= 1'b0; e2_q <= 1'b0; e3_q <= 1'b0; e4_q <= 1'b0; hm_eof_o   <= 1'b0;
            hm_sat_o    <= {COLS{1'b0}};
            pg_q        <= {(NG*PSW){1'b0}};
            pop_q       <= {PSW{1'b0}};
            sat_flag_o  <= 1'b0;
            sat_count_o <= {CNT_W{1'b0}};
        end else begin
            v1_q <= hm_valid_i; v2_q <= v1_q; v3_q <= v2_q; v4_q <= v3_q; hm_valid_o <= v4_q;
            e1_q <= hm_eof_i;   e2_q <= e1_q; e3_q <= e2_q; e4_q <= e3_q; hm_eof_o   <= e4_q;
            hm_sat_o <= v4_q ? sat5 : {COLS{1'b0}};
            if (sat_clr_i) begin
                pg_q        <= {(NG*PSW){1'b0}};
                pop_q       <= {PSW{1'b0}};
                sat_flag_o  <= 1'b0;
                sat_count_o <= {CNT_W{1'b0}};
            end else begin
                pg_q  <= pg_d;
                pop_q <= pop_d;
                if (|hm_sat_o) sat_flag_o <= 1'b1;
                sat_count_o <= cnt_sum[CNT_W] ? {CNT_W{1'b1}} : cnt_sum[CNT_W-1:0];
            end
        end
    end

endmodule

`default_nettype wire
