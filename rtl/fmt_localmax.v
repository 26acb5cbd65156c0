// fmt_localmax -- coarse touches: strict 3x3 local maxima above a threshold, with the
// raster-order tie rule, streamed out strongest first (twin: sim/fmt/localmax.py).
//
// Rule: cell p is a maximum iff z[p] >= threshold_i and, for every neighbour q on the
// sensor (Moore 8 or Von Neumann 4, moore_i): z[p] > z[q] when q precedes p in raster
// order (row above, or left), z[p] >= z[q] when q follows it (right, or row below).
// Missing neighbours (edges, corners) do not disqualify.  Two equal neighbouring cells
// give exactly one maximum (the first in raster order).
//
// Heat-map stream in (docs/ARCHITECTURE.md): rows in ANY order, one per cycle at most.
// Storage: the rows are written into an inferred RAM of 2 x ROWS words of COLS*HM_W
// bits (two frame buffers: the next frame's rows may arrive while the current frame is
// still being finished) with 3 synchronous read ports (rows r-1, r, r+1): block RAM,
// one copy per read port (27 RAMB36 at 30 x 40), no LUTs.  An arrival
// bitmap per buffer marks the rows present; row r is "ready" as soon as it and its
// existing neighbour rows are present, so evaluation runs while the frame arrives:
//   E0: pick the lowest ready row, read rows r-1, r, r+1          (1 row per cycle)
//   E1: compare every cell of row r with its neighbours -> maxima mask (COLS bits)
//   E2: serialise the maxima, one per cycle (lowest column first)
//   E3: insert (z, row, col) into a sorted list of MAX_TOUCHES entries (z descending,
//       ties by raster index ascending; fmt_sorted_list); the weakest falls off the end.
// After the frame's hm_eof, once every row is evaluated, the list is emitted, one
// candidate per cycle: the same three read ports fetch the candidate's rows and a
// column select forms its 3x3 neighbourhood (by column mod 3: three ceil((COLS+2)/3):1
// selects and a rotation per row); then cand_eof.  Settings (threshold_i,
// moore_i, limit_i) are used live: change them between frames.
//
// Latency (processing-clock cycles, measured by tb/fmt_localmax, rows one per cycle,
// hm_eof right after the last row): last row beat -> last candidate = 7 + n cycles
// for n candidates (1 -> 8, 5 -> 12), plus one cycle per maximum that lies in the rows
// completed by the last beat (16 maxima all in the last row: 42); hm_eof -> last
// candidate is one cycle less; cand_eof follows the last candidate.  Throughput: one
// row per cycle plus one cycle per maximum; a frame must be finished (cand_eof) before
// the frame after the next one starts to arrive, else overrun_o is set (sticky).
//
// Candidate stream: cand_valid_o with cand_frame_o, cand_row_o, cand_col_o, cand_z_o
// (the 3x3 neighbourhood, k = (dy+1)*3 + (dx+1) at [k*HM_W +: HM_W], 0 outside the
// sensor) and cand_missing_o (bit k = neighbour outside); then a one-cycle cand_eof_o
// (also for a frame without candidates) with cand_count_o (emitted), cand_found_o
// (maxima before the limit), cand_overflow_o (found > limit) and cand_incomplete_o (the
// frame missed rows, e.g. after a reset in its middle: no candidates are emitted).
`default_nettype none
`include "fmt_defaults.vh"

module fmt_localmax #(
    parameter ROWS        = `FMT_ROWS,          // heat-map rows
    parameter COLS        = `FMT_COLS,          // heat-map columns
    parameter HM_W        = `FMT_HM_W,          // cell width, unsigned
    parameter MAX_TOUCHES = `FMT_MAX_TOUCHES,   // candidate list length (contact limit)
    parameter FRAME_W     = 16,                 // frame number width
    parameter CNT_W       = 16,                 // dropped-candidate counter width (>= FOUND_W)
    parameter ROW_IDX_W   = (ROWS > 1) ? $clog2(ROWS) : 1,         // row index width
    parameter COL_IDX_W   = (COLS > 1) ? $clog2(COLS) : 1,         // column index width
    parameter LIM_W       = $clog2(MAX_TOUCHES + 1),               // limit / count width
    parameter FOUND_W     = $clog2(ROWS * COLS + 1)                // maxima counter width
) (
    input  wire                   clk,
    input  wire                   rst,              // synchronous, active high
    // settings
    input  wire [HM_W-1:0]        threshold_i,      // z >= threshold_i may be a touch
    input  wire                   moore_i,          // 1 = Moore (8 neighbours), 0 = Von Neumann (4)
    input  wire [LIM_W-1:0]       limit_i,          // contact limit (values > MAX_TOUCHES act as MAX_TOUCHES)
    // heat-map stream in
    input  wire                   hm_valid_i,       // one row this cycle
    input  wire [ROW_IDX_W-1:0]   hm_row_i,         // row index
    input  wire [FRAME_W-1:0]     hm_frame_i,       // frame number (taken with hm_eof_i)
    input  wire [COLS*HM_W-1:0]   hm_data_i,        // column c at [c*HM_W +: HM_W]
    input  wire                   hm_eof_i,         // end of frame
    // candidate stream out
    output reg                    cand_valid_o,     // one candidate
    output reg  [FRAME_W-1:0]     cand_frame_o,     // frame number (with cand_valid_o and cand_eof_o)
    output reg  [ROW_IDX_W-1:0]   cand_row_o,       // row of the maximum
    output reg  [COL_IDX_W-1:0]   cand_col_o,       // column of the maximum
    output reg  [9*HM_W-1:0]      cand_z_o,         // 3x3 neighbourhood
    output reg  [8:0]             cand_missing_o,   // 1 = neighbour k outside the sensor
    output reg                    cand_eof_o,       // after the frame's last candidate
    output reg  [LIM_W-1:0]       cand_count_o,     // candidates emitted (with cand_eof_o)
    output reg  [FOUND_W-1:0]     cand_found_o,     // maxima found (with cand_eof_o)
    output reg                    cand_overflow_o,  // found > limit (with cand_eof_o)
    output reg                    cand_incomplete_o,// frame had missing rows (with cand_eof_o)
    // monitor
    output reg                    overflow_flag_o,  // sticky: some frame exceeded the limit
    output reg  [CNT_W-1:0]       drop_count_o,     // candidates dropped (saturating)
    output reg                    overrun_o         // sticky: frames arrived faster than processed
);

    localparam K      = MAX_TOUCHES;
    localparam ADDR_W = $clog2(2 * ROWS);
    localparam RW     = COLS * HM_W;
    localparam IDX_W  = ROW_IDX_W + COL_IDX_W;    // raster key {row, col}
    localparam Z9_W   = 9 * HM_W;
    localparam integer LAST_ROW_I = ROWS - 1;
    localparam integer LAST_COL_I = COLS - 1;
    localparam integer ROWS_I     = ROWS;
    localparam integer K_I        = MAX_TOUCHES;
    localparam [ROW_IDX_W-1:0] LAST_ROW = LAST_ROW_I[ROW_IDX_W-1:0];
    localparam [COL_IDX_W-1:0] LAST_COL = LAST_COL_I[COL_IDX_W-1:0];
    localparam [ADDR_W-1:0]    ROWS_A   = ROWS_I[ADDR_W-1:0];
    localparam [LIM_W-1:0]     K_L      = K_I[LIM_W-1:0];

    // ---- frame buffers and arrival bookkeeping ----------------------------------------
    (* ram_style = "block" *)                 // one write, three reads: block RAM, one
    reg [RW-1:0]         mem [0:2*ROWS-1];  // copy per read port (no LUTs)
    reg [ROWS-1:0]       arr_q [0:1];       // rows present, per buffer
    reg [1:0]            eofs_q;            // hm_eof seen, per buffer
    reg [FRAME_W-1:0]    frm_q [0:1];       // frame number, per buffer
    reg                  wb_q;              // buffer receiving rows
    reg                  pb_q;              // buffer being processed
    reg [ROWS-1:0]       done_q;            // rows of pb issued for evaluation

    wire [ADDR_W-1:0] wr_row  = {{(ADDR_W-ROW_IDX_W){1'b0}}, hm_row_i};
    wire [ADDR_W-1:0] wr_addr = wb_q ? (ROWS_A + wr_row) : wr_row;
    always @(posedge clk) begin
        if (hm_valid_i) mem[wr_addr] <= hm_data_i;
    end

    // ready rows of the processing buffer
    wire [ROWS-1:0] arr_p = arr_q[pb_q];
    reg  [ROWS-1:0] ready;
    // (loop variables are local to their always block: one driver each, no latch)
    always @(*) begin : c_ready
        integer i;
        for (i = 0; i < ROWS; i = i + 1)
            ready[i] = arr_p[i] & ~done_q[i]
                     & ((i == 0)        ? 1'b1 : arr_p[(i == 0) ? 0 : i - 1])
                     & ((i == ROWS - 1) ? 1'b1 : arr_p[(i == ROWS - 1) ? i : i + 1]);
    end
    reg [ROW_IDX_W-1:0] pick;
    always @(*) begin : c_pick
        integer i;
        pick = {ROW_IDX_W{1'b0}};
        for (i = ROWS - 1; i >= 0; i = i - 1)
            if (ready[i]) pick = i[ROW_IDX_W-1:0];
    end
    // ---- state ------------------------------------------------------------------------
    localparam S_RUN = 1'b0, S_EMIT = 1'b1;
    reg state_q;

    // pipeline valids
    reg e1_v_q, e2_v_q, e3_v_q;
    wire [COLS-1:0] mask_next;
    reg  [COLS-1:0] mask_q;
    wire e2_free = !e2_v_q || ((mask_q & (mask_q - 1'b1)) == {COLS{1'b0}});
    wire e1_adv  = e1_v_q && e2_free;
    wire issue   = (state_q == S_RUN) && (|ready) && (!e1_v_q || e1_adv);

    // ---- the sorted list (z, raster index): fmt_sorted_list, below ------------------------
    /* verilator lint_off UNUSEDSIGNAL */     // only entry 0's raster index is read
    wire [K*IDX_W-1:0] l_idx;                 // raster index {row, col} of entry i
    /* verilator lint_on UNUSEDSIGNAL */
    reg [FOUND_W-1:0] found_q;
    reg [LIM_W-1:0]   left_q;                 // candidates still to emit
    wire              em_issue = (state_q == S_EMIT) && (left_q != {LIM_W{1'b0}});
    wire [ROW_IDX_W-1:0] l_row0 = l_idx[COL_IDX_W +: ROW_IDX_W];

    // ---- E0 -> E1: three synchronous reads (evaluation, or a candidate's 3x3 at emission)
    reg [RW-1:0]        ra_q, rb_q, rc_q;       // rows r-1, r, r+1
    reg [ROW_IDX_W-1:0] r1_q;
    wire [ROW_IDX_W-1:0] rd_row = (state_q == S_EMIT) ? l_row0 : pick;
    wire [ADDR_W-1:0] base  = pb_q ? ROWS_A : {ADDR_W{1'b0}};
    wire [ADDR_W-1:0] a_mid = base + {{(ADDR_W-ROW_IDX_W){1'b0}}, rd_row};
    wire [ADDR_W-1:0] a_up  = (rd_row == {ROW_IDX_W{1'b0}}) ? a_mid : a_mid - 1'b1;
    wire [ADDR_W-1:0] a_dn  = (rd_row == LAST_ROW) ? a_mid : a_mid + 1'b1;
    always @(posedge clk) begin
        if (issue || em_issue) begin
            ra_q <= mem[a_up];
            rb_q <= mem[a_mid];
            rc_q <= mem[a_dn];
            r1_q <= rd_row;
        end
    end
    wire top1 = (r1_q == {ROW_IDX_W{1'b0}});
    wire bot1 = (r1_q == LAST_ROW);

    // ---- E1: maxima mask of row r1 ----------------------------------------------------
    // gt_l[c] = B[c] > B[c-1] (c beats its left neighbour); the left neighbour beats
    // (>=) c exactly when !gt_l[c]: one comparator per horizontal pair.
    wire [COLS:0] gt_l;
    assign gt_l[0]    = 1'b1;
    assign gt_l[COLS] = 1'b0;
    genvar c;
    generate
        for (c = 1; c < COLS; c = c + 1) begin : g_h
            assign gt_l[c] = (rb_q[c*HM_W +: HM_W] > rb_q[(c-1)*HM_W +: HM_W]);
        end
        for (c = 0; c < COLS; c = c + 1) begin : g_cmp
            wire [HM_W-1:0] p  = rb_q[c*HM_W +: HM_W];
            wire [HM_W-1:0] u  = ra_q[c*HM_W +: HM_W];
            wire [HM_W-1:0] d  = rc_q[c*HM_W +: HM_W];
            wire ok_thr = (p >= threshold_i);
            wire ok_u   = top1 || (p > u);
            wire ok_d   = bot1 || (p >= d);
            wire ok_l   = gt_l[c];
            wire ok_r   = !gt_l[c + 1];
            wire ok_ul, ok_ur, ok_dl, ok_dr;
            if (c > 0) begin : g_l
                wire [HM_W-1:0] ul = ra_q[(c-1)*HM_W +: HM_W];
                wire [HM_W-1:0] dl = rc_q[(c-1)*HM_W +: HM_W];
                assign ok_ul = top1 || !moore_i || (p > ul);
                assign ok_dl = bot1 || !moore_i || (p >= dl);
            end else begin : g_nl
                assign ok_ul = 1'b1;  assign ok_dl = 1'b1;
            end
            if (c < COLS - 1) begin : g_r
                wire [HM_W-1:0] ur = ra_q[(c+1)*HM_W +: HM_W];
                wire [HM_W-1:0] dr = rc_q[(c+1)*HM_W +: HM_W];
                assign ok_ur = top1 || !moore_i || (p > ur);
                assign ok_dr = bot1 || !moore_i || (p >= dr);
            end else begin : g_nr
                assign ok_ur = 1'b1;  assign ok_dr = 1'b1;
            end
            assign mask_next[c] = ok_thr & ok_u & ok_d & ok_l & ok_r & ok_ul & ok_ur & ok_dl & ok_dr;
        end
    endgenerate

    // ---- E2: serialise the maxima of the row (lowest column first) -------------------
    reg [RW-1:0]        wrow_q;                 // the evaluated row (values for sorting)
    reg [ROW_IDX_W-1:0] r2_q;
    reg [COL_IDX_W-1:0] sel;                    // lowest set bit of mask_q
    always @(*) begin : c_sel
        integer i;
        sel = {COL_IDX_W{1'b0}};
        for (i = COLS - 1; i >= 0; i = i - 1)
            if (mask_q[i]) sel = i[COL_IDX_W-1:0];
    end
    wire [HM_W-1:0] sel_z = wrow_q[sel*HM_W +: HM_W];

    // E3 candidate register
    reg [HM_W-1:0]  n_z_q;
    reg [IDX_W-1:0] n_idx_q;

    // ---- E3: insertion into the list (z descending, raster index ascending); the
    // emission pops entry 0, one per candidate; the frame's release clears the list
    wire releasing;
    /* verilator lint_off UNUSEDSIGNAL */     // the emission reads entry 0's index only
    wire [K-1:0]      l_v;
    wire [K*HM_W-1:0] l_z;
    wire [K-1:0]      l_pay;                  // no payload (PAY_W = 0: constant 0)
    wire              l_drop;
    /* verilator lint_on UNUSEDSIGNAL */
    fmt_sorted_list #(.K(K), .KEY_W(HM_W), .TIE_W(IDX_W), .PAY_W(0), .PAY_RST_IDX(0),
                      .HAS_POP(1)) u_list (
        .clk(clk), .rst(rst), .clear_i(releasing),
        .ins_i(e3_v_q), .ins_key_i(n_z_q), .ins_tie_i(n_idx_q), .ins_pay_i(1'b0),
        .pop_i(em_issue), .valid_o(l_v), .key_o(l_z), .tie_o(l_idx), .pay_o(l_pay),
        .drop_pay_o(l_drop));

    // ---- emission: 3x3 of the candidate read back in E1, column select ---------------
    reg                 em_v_q, em_eof_q;
    reg [ROW_IDX_W-1:0] em_row_q;
    reg [COL_IDX_W-1:0] em_col_q;
    reg [FRAME_W-1:0]   em_frame_q;
    reg [Z9_W-1:0] z9;
    reg [8:0]      miss9;
    // The three rows padded with a zero cell at each end (padded cell p = column p - 1);
    // the candidate's window is padded cells p0 .. p0 + 2, p0 = em_col_q.  The padded
    // cells are split by p mod 3 into three groups of NGR cells (cell j of group g is
    // p = 3j + g, 0 beyond the row): the window holds exactly one cell of each group,
    // cell q or q + 1 (q = p0 / 3, m = p0 mod 3: q + 1 for the groups g < m), and window
    // position k takes group (m + k) mod 3.  Three NGR : 1 selects and a 3 : 1 rotation
    // per row and bit instead of three (COLS + 2) : 1 selects.
    localparam NPC  = COLS + 2;
    localparam NGR  = (NPC + 2) / 3;
    localparam QI_W = $clog2(NGR + 1);
    localparam NGA  = 1 << QI_W;
    reg [QI_W-1:0] em_q_q;                     // em_col_q / 3
    reg [1:0]      em_m_q;                     // em_col_q mod 3
    wire [HM_W-1:0] ga0 [0:NGA-1], ga1 [0:NGA-1], ga2 [0:NGA-1];
    wire [HM_W-1:0] gb0 [0:NGA-1], gb1 [0:NGA-1], gb2 [0:NGA-1];
    wire [HM_W-1:0] gc0 [0:NGA-1], gc1 [0:NGA-1], gc2 [0:NGA-1];
    genvar gj;
    generate
        for (gj = 0; gj < NGA; gj = gj + 1) begin : g_grp
            // padded cell 3j + g is column 3j + g - 1
            if (3 * gj >= 1 && 3 * gj <= COLS) begin : g_0
                assign ga0[gj] = ra_q[(3*gj-1)*HM_W +: HM_W];
                assign gb0[gj] = rb_q[(3*gj-1)*HM_W +: HM_W];
                assign gc0[gj] = rc_q[(3*gj-1)*HM_W +: HM_W];
            end else begin : g_0z
                assign ga0[gj] = {HM_W{1'b0}};
                assign gb0[gj] = {HM_W{1'b0}};
                assign gc0[gj] = {HM_W{1'b0}};
            end
            if (3 * gj + 1 <= COLS) begin : g_1
                assign ga1[gj] = ra_q[(3*gj)*HM_W +: HM_W];
                assign gb1[gj] = rb_q[(3*gj)*HM_W +: HM_W];
                assign gc1[gj] = rc_q[(3*gj)*HM_W +: HM_W];
            end else begin : g_1z
                assign ga1[gj] = {HM_W{1'b0}};
                assign gb1[gj] = {HM_W{1'b0}};
                assign gc1[gj] = {HM_W{1'b0}};
            end
            if (3 * gj + 2 <= COLS) begin : g_2
                assign ga2[gj] = ra_q[(3*gj+1)*HM_W +: HM_W];
                assign gb2[gj] = rb_q[(3*gj+1)*HM_W +: HM_W];
                assign gc2[gj] = rc_q[(3*gj+1)*HM_W +: HM_W];
            end else begin : g_2z
                assign ga2[gj] = {HM_W{1'b0}};
                assign gb2[gj] = {HM_W{1'b0}};
                assign gc2[gj] = {HM_W{1'b0}};
            end
        end
    endgenerate
    wire [QI_W-1:0] gi0 = em_q_q + {{(QI_W-1){1'b0}}, (em_m_q > 2'd0)};   // group 0
    wire [QI_W-1:0] gi1 = em_q_q + {{(QI_W-1){1'b0}}, (em_m_q > 2'd1)};   // group 1
    wire [HM_W-1:0] sa0 = ga0[gi0], sa1 = ga1[gi1], sa2 = ga2[em_q_q];
    wire [HM_W-1:0] sb0 = gb0[gi0], sb1 = gb1[gi1], sb2 = gb2[em_q_q];
    wire [HM_W-1:0] sc0 = gc0[gi0], sc1 = gc1[gi1], sc2 = gc2[em_q_q];
    // quotient and remainder by 3 of a column index (for em_q_q, em_m_q)
    wire [COL_IDX_W-1:0] nx_col = l_idx[0 +: COL_IDX_W];
    reg  [QI_W-1:0]      nx_q;
    reg  [1:0]           nx_m;
    integer k3, colv, qv;
    always @(*) begin
        colv = {{(32-COL_IDX_W){1'b0}}, nx_col};
        qv = 0;
        for (k3 = 1; k3 < NGA; k3 = k3 + 1)
            if (colv >= 3 * k3) qv = k3;
        nx_q = qv[QI_W-1:0];
        colv = colv - 3 * qv;
        nx_m = colv[1:0];
    end
    always @(*) begin
        case (em_m_q)
            2'd1:    z9 = {sc0, sc2, sc1, sb0, sb2, sb1, sa0, sa2, sa1};
            2'd2:    z9 = {sc1, sc0, sc2, sb1, sb0, sb2, sa1, sa0, sa2};
            default: z9 = {sc2, sc1, sc0, sb2, sb1, sb0, sa2, sa1, sa0};
        endcase
        miss9 = 9'd0;
        if (em_col_q == {COL_IDX_W{1'b0}})     miss9 = miss9 | 9'b001_001_001;
        if (em_col_q == LAST_COL)              miss9 = miss9 | 9'b100_100_100;
        if (em_row_q == {ROW_IDX_W{1'b0}})     miss9 = miss9 | 9'b000_000_111;
        if (em_row_q == LAST_ROW)              miss9 = miss9 | 9'b111_000_000;
        if (em_row_q == {ROW_IDX_W{1'b0}}) z9[0 +: 3*HM_W]      = {(3*HM_W){1'b0}};
        if (em_row_q == LAST_ROW)          z9[6*HM_W +: 3*HM_W] = {(3*HM_W){1'b0}};
    end

    wire [LIM_W-1:0] lim_eff  = (limit_i > K_L) ? K_L : limit_i;
    wire [FOUND_W-1:0] lim_ext = {{(FOUND_W > LIM_W ? FOUND_W - LIM_W : 0){1'b0}}, lim_eff};
    wire             over     = (found_q > lim_ext);
    wire [LIM_W-1:0] n_emit   = over ? lim_eff : found_q[LIM_W-1:0];
    wire             complete = (arr_p == {ROWS{1'b1}});
    wire             finish   = (state_q == S_RUN) && eofs_q[pb_q] && !(|ready)
                              && !e1_v_q && !e2_v_q && !e3_v_q;
    wire [FOUND_W-1:0] dropped = found_q - {{(FOUND_W > LIM_W ? FOUND_W - LIM_W : 0){1'b0}}, n_emit};
    assign           releasing = (state_q == S_EMIT) && (left_q == {LIM_W{1'b0}});
    wire [CNT_W:0]   drop_sum = {1'b0, drop_count_o} + {{(CNT_W + 1 - FOUND_W){1'b0}}, dropped};

    always @(posedge clk) begin
        // ---- datapath registers (no reset needed) ----
        if (e1_adv) begin
            wrow_q <= rb_q;
            r2_q   <= r1_q;
        end
        n_z_q   <= sel_z;
        n_idx_q <= {r2_q, sel};
        cand_z_o       <= z9;
        cand_missing_o <= miss9;
        cand_row_o     <= em_row_q;
        cand_col_o     <= em_col_q;
        cand_frame_o   <= em_frame_q;

        if (rst) begin
            arr_q[0] <= {ROWS{1'b0}};
            arr_q[1] <= {ROWS{1'b0}};
            eofs_q   <= 2'b00;
            wb_q     <= 1'b0;
            pb_q     <= 1'b0;
            done_q   <= {ROWS{1'b0}};
            state_q  <= S_RUN;
            e1_v_q   <= 1'b0;
            e2_v_q   <= 1'b0;
            e3_v_q   <= 1'b0;
            mask_q   <= {COLS{1'b0}};
            found_q  <= {FOUND_W{1'b0}};
            left_q   <= {LIM_W{1'b0}};
            em_v_q   <= 1'b0;
            em_eof_q <= 1'b0;
            em_row_q <= {ROW_IDX_W{1'b0}};
            em_col_q <= {COL_IDX_W{1'b0}};
            em_q_q   <= {QI_W{1'b0}};
            em_m_q   <= 2'd0;
            cand_valid_o      <= 1'b0;
            cand_eof_o        <= 1'b0;
            cand_count_o      <= {LIM_W{1'b0}};
            cand_found_o      <= {FOUND_W{1'b0}};
            cand_overflow_o   <= 1'b0;
            cand_incomplete_o <= 1'b0;
            overflow_flag_o   <= 1'b0;
            drop_count_o      <= {CNT_W{1'b0}};
            overrun_o         <= 1'b0;
        end else begin
            // ---- arrivals ----
            if (hm_valid_i) arr_q[wb_q][hm_row_i] <= 1'b1;
            if (hm_eof_i) begin
                eofs_q[wb_q] <= 1'b1;
                frm_q[wb_q]  <= hm_frame_i;
                wb_q         <= ~wb_q;
                // the other buffer still holds an unfinished frame: it will be overwritten
                if (pb_q != wb_q && !releasing) overrun_o <= 1'b1;
            end

            // ---- E0/E1 ----
            if (issue) begin
                done_q[pick] <= 1'b1;
                e1_v_q <= 1'b1;
            end else if (e1_adv) begin
                e1_v_q <= 1'b0;
            end

            // ---- E2 ----
            e3_v_q <= e2_v_q && (|mask_q);
            if (e2_free) begin
                e2_v_q <= e1_v_q;
                mask_q <= e1_v_q ? mask_next : {COLS{1'b0}};
            end else begin
                mask_q <= mask_q & (mask_q - 1'b1);      // clear the lowest set bit
            end

            // ---- E3: count (the list inserts) ----
            if (e3_v_q) found_q <= found_q + 1'b1;

            // ---- finish and emit ----
            if (finish) begin
                state_q    <= S_EMIT;
                em_frame_q <= frm_q[pb_q];
                left_q     <= complete ? n_emit : {LIM_W{1'b0}};
                cand_count_o      <= complete ? n_emit : {LIM_W{1'b0}};
                cand_found_o      <= complete ? found_q : {FOUND_W{1'b0}};
                cand_overflow_o   <= complete && over;
                cand_incomplete_o <= !complete;
                if (complete && over) begin
                    overflow_flag_o <= 1'b1;
                    drop_count_o    <= drop_sum[CNT_W] ? {CNT_W{1'b1}} : drop_sum[CNT_W-1:0];
                end
            end
            // emission pipeline: em_issue reads the rows (E1 registers), then the column
            // select registers the candidate; cand_eof follows the last one
            em_v_q       <= em_issue;
            em_eof_q     <= releasing;
            cand_valid_o <= em_v_q;
            cand_eof_o   <= em_eof_q;
            if (em_issue) begin
                em_row_q <= l_row0;
                em_col_q <= nx_col;
                em_q_q   <= nx_q;
                em_m_q   <= nx_m;
                left_q   <= left_q - 1'b1;      // the list pops entry 0
            end
            if (releasing) begin
                state_q      <= S_RUN;      // the list is cleared
                found_q      <= {FOUND_W{1'b0}};
                done_q       <= {ROWS{1'b0}};
                arr_q[pb_q]  <= {ROWS{1'b0}};
                eofs_q[pb_q] <= 1'b0;
                pb_q         <= ~pb_q;
            end
        end
    end

endmodule

`default_nettype wire
