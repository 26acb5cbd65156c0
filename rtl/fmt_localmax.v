// fmt_localmax -- coarse touches: strict 3x3 local maxima above a threshold, with the
// raster-order tie rule, streamed out continuing first, then strongest first (twin:
// sim/fmt/localmax.py, LocalMaxima).
//
// Rule: cell p is a maximum iff z[p] >= threshold_i and, for every neighbour q on the
// sensor (Moore 8 or Von Neumann 4, moore_i): z[p] > z[q] when q precedes p in raster
// order (row above, or left), z[p] >= z[q] when q follows it (right, or row below).
// Missing neighbours (edges, corners) do not disqualify.  Two equal neighbouring cells
// give exactly one maximum (the first in raster order).
// Contact limit with hysteresis on the ranking (issue #11 item 3): a maximum within one
// cell (|dr| <= 1, |dc| <= 1) of a candidate the previous frame emitted is continuing
// and ranks ahead of every new one; then z descending, then raster index ascending.  The
// first limit_i in that order are emitted in that order, so N + 1 fingers under a limit
// of N give the same N every frame.  No candidate is continuing after a reset or an
// incomplete frame.
//
// Heat-map stream in (docs/ARCHITECTURE.md): rows in ANY order, one per cycle at most.
// Storage: the rows are written into an inferred RAM of 2 x 2^ROW_IDX_W words of
// COLS*HM_W bits (two frame buffers, word {buffer, row}: the next frame's rows may
// arrive while the current frame is still being finished) with ONE read port: block
// RAM, 9 RAMB36 at 30 x 40 (the width, one row written per cycle, sets the count), read
// through a second (output) register as XST packs it.  An arrival bitmap per buffer
// marks the rows present; row r is "ready" when it and its existing neighbour rows are
// present, so evaluation runs while the frame arrives.  Evaluation sweeps down the rows,
// one row read per step (SW = sweep):
//   SW0  choose the step: finish the current row r (read r + 1; after the last row a
//        virtual step without a read), move on to a ready r + 1, or start at the lowest
//        ready row s (read s - 1, then s, then s + 1: 3 reads, 1 per row after that);
//        address register (the finish and move-on rules are registers, computed a cycle
//        early for each row the step can leave as r: r, r + 1 or s)
//   SW1  block-RAM read, SW2 its output register (N, the new row)
//   SW3  one comparator bank against the previous step's row P = N's row - 1 (the
//        window register w0): N > P, N > P left, N > P right, N > N left, N >= threshold
//        (5 x COLS comparators; each pair of cells is compared once: P's "below" tests
//        are the negations of N's "above" tests), registered when the window shifts
//        (w2 <- w1 <- w0 <- N: w2, w1, w0 = rows P - 1, P, P + 1), each comparator's
//        output in a register of its own (no gate between them): N's above test and
//        partial mask (earlier neighbours) and P's down mask (its later neighbours in N)
//        are functions of these registers.
//   SW4  serialise P's maxima, lowest column first, one per cycle: P's partial mask
//        (loaded at the shift) AND its down mask; the lowest maximum is registered
//        one-hot and decoded in the next cycle (the sweep waits: a row with k maxima
//        holds the window k cycles, a row with none but a non-empty partial mask one
//        cycle, a row with two partial-mask cells or more and at most one maximum two
//        cycles; the stall enable is a register, computed a cycle early from the partial
//        mask and the serialiser's own bits (two or more left: the first cycle of a row
//        counts its partial mask, not its maxima), in copies per column group: no
//        comparator and no gate before the window's clock enables)
//   SW5  capture the maximum's 3x3 from the window (by column mod 3: three
//        ceil((COLS+2)/3):1 selects per row, in two registered steps: a select within
//        each quarter of a group (its select decoded per quarter from the one-hot
//        lowest maximum), then the quarter;
//        then a rotation per row and the rows outside the sensor, registered)
//   SW6  insert ({continuing, z}, raster index, slot) into a sorted list of MAX_TOUCHES
//        entries (key descending, ties by raster index ascending; the continuing flag
//        from a row test when the window shifts and a column test in the capture's first
//        step, against the previous frame's candidates, recorded as they were emitted,
//        K x (row, column); fmt_sorted_list, comparing a cycle
//        early with the centre cell from registers of its own, rotated in the capture's
//        second step, in four copies for the list's comparators); the 3x3 goes to a
//        (MAX_TOUCHES+1)-slot store (block RAM) at the list's free slot.
// After the frame's hm_eof, once every ready row is finished, the list is emitted, one
// candidate per cycle: pop entry 0, read its 3x3 from the slot store, output registers;
// then cand_eof.  Settings (threshold_i, moore_i, limit_i) are taken with the rows, per
// frame buffer: a frame is processed with the values its rows arrived with (hold them
// constant over a frame's rows; fmt_touch gives every frame the settings of its first
// row), also while the next frame arrives.
//
// Latency (processing-clock cycles, measured by tb/fmt_localmax, rows one per cycle,
// hm_eof right after the last row, the earlier rows finished): last row beat -> last
// candidate <= 15 + n + m + e for n candidates, m maxima in the rows completed by the
// last beat (its row and the rows next to it) and e (<= 6) the extra stall cycles of
// those rows: one for a row with a partial mask but no maximum, one more for a row with
// two partial-mask cells or more and at most one maximum: the sweep starts over (up to
// 5 reads: rows r - 2 .. r + 2) on one-cycle-old ready flags, each maximum holds it one
// cycle (plus the extra cycles above), the last one is captured (3 registers) and
// inserted, and the finish test is registered, before the emission starts.  30 x 40,
// FFT row order: 12 + n + e without maxima in those rows (3..5 candidates: 15, 16, 15,
// 18); 20 maxima in the last row, 16 candidates: 51 (= 15 + n + m).  hm_eof -> last
// candidate is one cycle less; cand_eof follows the last candidate.
// Worst-case cycles per frame (30 x 40, M = 1): at most 4 steps per row (a start: one
// idle cycle for the one-cycle-old lowest ready row, reads s - 1, s, s + 1; one read
// per row in a run) plus the virtual step (121), per row max(k, min(p, 2)) for k
// maxima and p partial-mask cells (k <= p <= COLS / 2 = 20: no two neighbours in a
// partial mask; 600: Von Neumann checkerboard, 20 maxima a row), 11 of pipeline and
// finish, n + 3 of emission (19): 751 < 768.
// A frame must be finished (cand_eof) before the frame after the next one starts to
// arrive, else overrun_o is set (sticky).
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
    parameter ROWS        = `FMT_ROWS,          // heat-map rows (>= 2)
    parameter COLS        = `FMT_COLS,          // heat-map columns (>= 2)
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
    localparam RW     = COLS * HM_W;
    localparam IDX_W  = ROW_IDX_W + COL_IDX_W;    // raster key {row, col}
    localparam Z9_W   = 9 * HM_W;
    localparam KEY_W  = HM_W + 1;             // the list's key {continuing, z}
    localparam AW     = ROW_IDX_W + 1;            // frame-store address {buffer, row}
    localparam SLOT_W = $clog2(K + 1);            // 3x3 store slot (K + 1 slots)
    localparam integer LAST_ROW_I = ROWS - 1;
    localparam integer LAST_COL_I = COLS - 1;
    localparam integer K_I        = MAX_TOUCHES;
    localparam [ROW_IDX_W-1:0] LAST_ROW = LAST_ROW_I[ROW_IDX_W-1:0];
    localparam [COL_IDX_W-1:0] LAST_COL = LAST_COL_I[COL_IDX_W-1:0];
    localparam [LIM_W-1:0]     K_L      = K_I[LIM_W-1:0];

    // synthesis translate_off
    initial begin
        if (ROWS < 2 || COLS < 2) begin
            $display("fmt_localmax: ROWS %0d and COLS %0d must be >= 2", ROWS, COLS);
            $finish;
        end
    end
    // synthesis translate_on

    // ---- frame store and arrival bookkeeping ---------------------------------------------
    (* ram_style = "block" *)                  // one write port, one read port: block RAM
    reg [RW-1:0]      mem [0:(1 << AW)-1];     // word {buffer, row}
    reg [ROWS-1:0]    arr0_q, arr1_q;          // rows present, per buffer
    reg [1:0]         eofs_q;                  // hm_eof seen, per buffer
    reg [FRAME_W-1:0] frm0_q, frm1_q;          // frame number, per buffer
    reg               wb_q;                    // buffer receiving rows
    reg               pb_q;                    // buffer being processed

    always @(posedge clk) begin
        if (hm_valid_i) mem[{wb_q, hm_row_i}] <= hm_data_i;
    end

    // ---- settings, per frame buffer ----------------------------------------------------
    // threshold_i, moore_i and limit_i are taken with every row that arrives into a buffer
    // (the caller holds them constant over a frame's rows: fmt_touch does) and the sweep
    // and the finish use the values of the buffer being processed, from a register
    // (set_p_q = the set of buffer pb_q, one cycle old: a row is compared 4 cycles after
    // its arrival at the earliest, and the sweep of a buffer starts after the release of
    // the other one).  So a frame is processed with the settings it arrived with, also
    // while the next frame arrives.
    localparam SET_W = HM_W + 1 + LIM_W;       // {threshold, moore, limit}
    reg  [SET_W-1:0]  set0_q, set1_q;          // per buffer
    reg  [SET_W-1:0]  set_p_q;                 // the processing buffer's
    always @(posedge clk) begin
        if (rst) begin
            set0_q  <= {SET_W{1'b0}};
            set1_q  <= {SET_W{1'b0}};
            set_p_q <= {SET_W{1'b0}};
        end else begin
            if (hm_valid_i && !wb_q) set0_q <= {threshold_i, moore_i, limit_i};
            if (hm_valid_i &&  wb_q) set1_q <= {threshold_i, moore_i, limit_i};
            set_p_q <= pb_q ? set1_q : set0_q;
        end
    end
    wire [HM_W-1:0]   thr_p   = set_p_q[SET_W-1 -: HM_W];    // threshold of the frame
    wire              moore_p = set_p_q[LIM_W];              // moore of the frame
    wire [LIM_W-1:0]  limit_p = set_p_q[LIM_W-1:0];          // limit of the frame

    // the processing buffer's arrival bitmap, kept as its own register (= pb_q ? arr1_q :
    // arr0_q in every cycle; updated below with arr0_q / arr1_q)
    reg  [ROWS-1:0] arrp_q;
    wire [ROWS-1:0] arr_p = arrp_q;
    // the row arriving, one-hot: decoded bit by bit and gated by hm_valid_i, so an
    // undefined hm_row_i between beats (a datapath register upstream without reset is X
    // under Icarus) gives 0 and not X (a shift by an X amount would give all X bits)
    wire [ROWS-1:0] hm_1h;
    genvar gh;
    generate
        for (gh = 0; gh < ROWS; gh = gh + 1) begin : g_hm_1h
            localparam [ROW_IDX_W-1:0] RI = gh;
            assign hm_1h[gh] = hm_valid_i && (hm_row_i == RI);
        end
    endgenerate

    // ---- sweep scheduler ------------------------------------------------------------------
    // A step reads one row x of the processing buffer into the window.  The comparators
    // compare it (N) with the row of the previous step (P).  When P = x - 1 the step
    // yields N's partial mask (threshold, left/right, the row above) and, with fin, P's
    // final mask (P's partial and the row below).  A virtual step after the last row
    // finishes it without a read.
    localparam S_RUN = 1'b0, S_EMIT = 1'b1;
    reg state_q;
    reg [ROWS-1:0]      done_q;                // rows finished (mask issued)
    (* fsm_encoding = "none" *)             // small registers below: no FSM extraction
    reg [ROW_IDX_W-1:0] cur_q;                 // row of the latest step
    reg                 cv_q;                  // cur_q valid (a step since the frame began)
    reg                 cp_q;                  // the partial mask of cur_q is complete
    (* fsm_encoding = "none" *)
    reg [ROW_IDX_W-1:0] jx_q;                  // the row to read to start there
    reg                 rule_c_q;              // rule c (below), registered
    // The step pipeline advances when no maximum is being serialised (rem_q = 0) and
    // not in the cycle after a step that finished a row with a non-empty partial mask
    // (conservative: the mask's test against the row below, a comparator bank, is not
    // waited for).  The enable is a register, computed a cycle early (adv_d below), in
    // copies: the window's 1,960 flip-flops, the frame-store read register
    // and output register, the step pipeline and the serialiser each take their own, so
    // no enable net fans out from gates to thousands of flip-flops.
    localparam NWC = (COLS >= 5) ? COLS / 5 : 1;    // window-shift enable copies
    localparam NOC = (COLS >= 10) ? COLS / 10 : 1;  // output-register enable copies
    reg                 advc_q;                // adv: the step pipeline and the rules
    reg                 advs_q;                // adv: the serialiser
    reg                 advr_q;                // adv: the frame-store read register
    reg [NOC-1:0]       advo_q;                // adv: the output register, by column group
    reg [NWC-1:0]       wsh_q;                 // adv and v2_q: the window shifts, by column group
    wire                adv = advc_q;          // (rem_q == 0)

    // ready: present with its neighbours, not finished -- a register of its own (rdy_q,
    // loaded from the next values of arrp_q and done_q: equal to the same function of
    // arr_p and done_q in every cycle), so the lowest-ready-row carry starts at a
    // flip-flop, not after arr_p's fan-out and a gate
    reg  [ROWS-1:0] rdy_q;
    wire [ROWS-1:0] ready = rdy_q;
    reg [ROWS-1:0] fin_ok;                     // not finished and the row below present
    reg [ROWS-1:0] nxt_ok;                     // row i + 1 ready
    always @(*) begin : c_ready
        integer i;
        for (i = 0; i < ROWS; i = i + 1)
            fin_ok[i] = ~done_q[i] & ((i == ROWS - 1) ? 1'b1 : arr_p[(i == ROWS - 1) ? i : i + 1]);
        for (i = 0; i < ROWS; i = i + 1)
            nxt_ok[i] = (i == ROWS - 1) ? 1'b0 : ready[(i == ROWS - 1) ? i : i + 1];
    end
    // lowest ready row, as an OR of one-hot bits (no priority chain)
    wire [ROWS-1:0] rdy_low = ready & ~(ready - 1'b1);
    reg  [ROW_IDX_W-1:0] jx_d;
    /* verilator lint_off UNUSEDSIGNAL */     // integer temporaries: their low bits are used
    always @(*) begin : c_j
        integer i, t;
        t    = 0;
        jx_d = {ROW_IDX_W{1'b0}};
        for (i = 0; i < ROWS; i = i + 1)
            if (rdy_low[i]) begin
                t    = (i == 0) ? 0 : i - 1;
                jx_d = jx_d | t[ROW_IDX_W-1:0];
            end
    end
    /* verilator lint_on UNUSEDSIGNAL */

    // The rules read fin_ok, nxt_ok and the lowest ready row one cycle late (indexed by
    // one-hot rows).  Safe: rows only arrive in between, and the only row finished in the
    // last cycle is the previous cur, never indexed now (rule c checks its row against
    // done_q itself).  Rules a and b are registered: computed a cycle early for each row
    // the next cur can be (cur, cur + 1, the start row jx) and chosen by the step taken.
    reg [ROWS-1:0] cur1h_q;                    // cur_q one-hot
    reg [ROWS-1:0] jx1h_q;                     // jx_q one-hot
    reg            jx0_q;                      // jx_q = 0
    reg            rule_a_q, rule_b_q;         // rules a and b (below), registered
    wire run    = (state_q == S_RUN);
    wire rule_a = rule_a_q;                    // cv, cp and fin_ok[cur]: finish cur (read cur + 1)
    wire rule_b = rule_b_q;                    // cv and nxt_ok[cur]: move on to a ready cur + 1
    wire rule_c = rule_c_q;                    // some row j was ready and is not finished: start at j
    wire issue  = run && adv && (rule_a || rule_b || rule_c);
    wire last_c = cur1h_q[ROWS-1];
    wire [ROW_IDX_W-1:0] cur_p1 = cur_q + 1'b1;
    wire [ROW_IDX_W-1:0] x_row  = (rule_a || rule_b) ? cur_p1 : jx_q;
    wire [ROWS-1:0] jx1h_d = (rdy_low >> 1) | {{(ROWS-1){1'b0}}, rdy_low[0]};
    // rules a and b for the next cycle, per candidate next cur: unchanged, cur + 1, jx
    wire [ROWS-1:0] cur1h_up = cur1h_q << 1;
    wire a_hold = |(cur1h_q  & fin_ok),  b_hold = |(cur1h_q  & nxt_ok);
    wire a_up   = |(cur1h_up & fin_ok),  b_up   = |(cur1h_up & nxt_ok);
    wire a_jump = |(jx1h_q   & fin_ok),  b_jump = |(jx1h_q   & nxt_ok);
    wire ab     = rule_a || rule_b;        // the step reads cur + 1
    wire vstep  = rule_a && last_c;        // the virtual step: no cur after it

    // step pipeline: s0 address register, s1 block-RAM read, s2 its output register
    reg [AW-1:0]        a0_q;
    reg                 v0_q, v1_q, v2_q;      // step valid
    reg                 f0_q, f1_q, f2_q;      // finishes the previous row
    reg                 t0_q, t1_q, t2_q;      // the read row is row 0
    reg                 x0_q, x1_q, x2_q;      // virtual step (after the last row)
    reg [ROW_IDX_W-1:0] r0_q, r1_q, r2_q;      // row finished by the step
    reg [RW-1:0]        rd_q;                  // block-RAM read register
    reg [RW-1:0]        do_q;                  // block-RAM output register (N)
    reg [RW-1:0]        w0_q, w1_q, w2_q;      // window: rows x-1 (P), x-2, x-3 of the last step

    always @(posedge clk) begin
        if (advr_q) rd_q <= mem[a0_q];
    end

    // ---- comparators: P = w0_q, N = do_q --------------------------------------------------
    // Only registers follow them, each comparator's output its own (taken when the window
    // shifts, with N into w0_q): per column N > N left (cl_q), N >= threshold (ct_q), N >
    // P (cg_q), N > P left (g1_q) and N > P right (g2_q), no gate between a comparator and
    // its register.  N's test against its earlier neighbours in P (cu) and P's against
    // its later neighbours in N (dm: P's "down" mask) are functions of these registers;
    // N's partial mask is one too (part_c), and P's maxima are its partial mask AND dm,
    // applied in the serialiser.
    wire [COLS-1:0] gtl;                       // N[c] > N[c-1]
    wire [COLS-1:0] gtv;                       // N[c] > P[c]
    wire [COLS-1:1] gd1;                       // N[c] > P[c-1]
    wire [COLS-1:1] gd2;                       // N[c] > P[c+1] at [c+1]
    wire [COLS-1:0] thr_n;
    assign gtl[0] = 1'b1;
    genvar c;
    generate
        for (c = 0; c < COLS; c = c + 1) begin : g_cmp
            wire [HM_W-1:0] n = do_q[c*HM_W +: HM_W];
            wire [HM_W-1:0] p = w0_q[c*HM_W +: HM_W];
            assign gtv[c] = (n > p);
            if (c > 0) begin : g_l
                assign gtl[c] = (n > do_q[(c-1)*HM_W +: HM_W]);
                assign gd1[c] = (n > w0_q[(c-1)*HM_W +: HM_W]);
            end
            if (c < COLS - 1) begin : g_r
                assign gd2[c+1] = (n > w0_q[(c+1)*HM_W +: HM_W]);
            end
            assign thr_n[c] = (n >= thr_p);
        end
    endgenerate
    reg [COLS-1:0]  cl_q;                      // gtl of w0_q's row (cl_q[0] = 1)
    reg [COLS-1:0]  ct_q, cg_q;                // thr_n, gtv: w0_q's row against w1_q's
    reg [COLS-1:1]  g1_q, g2_q;                // gd1, gd2 (d1, d2 below: with the constant ends)
    reg             t3_q;                      // w0_q's row is row 0
    reg             mtop_q, mbot_q;            // w1_q is the first / last row
    wire [COLS:0]   cl = {1'b0, cl_q};
    wire [COLS:0]   d1 = {1'b0, g1_q, 1'b1};
    wire [COLS:0]   d2 = {1'b1, g2_q, 1'b0};
    // w0_q's row above its earlier neighbours in w1_q (above, above-left, above-right,
    // strict), and w1_q's row at least equal to its later neighbours in w0_q (below,
    // below-left, below-right; all of them when w1_q holds the last row)
    // (moore_p from registered copies, one per quarter of the columns: no net from one
    // flip-flop to the 80 mask LUTs)
    localparam NMC = (COLS >= 4) ? 4 : 1;      // moore_p copies
    reg  [NMC-1:0]  moo_q;
    wire [COLS-1:0] moo;                       // the copy of column c
    genvar gm;
    generate
        for (gm = 0; gm < NMC; gm = gm + 1) begin : g_moo
            (* keep *) always @(posedge clk) moo_q[gm] <= moore_p;
        end
        for (gm = 0; gm < COLS; gm = gm + 1) begin : g_mooc
            assign moo[gm] = moo_q[(gm * NMC) / COLS];
        end
    endgenerate
    wire [COLS-1:0] cu = cg_q & (~moo | (d1[COLS-1:0] & d2[COLS:1]));
    wire [COLS-1:0] dm = {COLS{mbot_q}} | (~cg_q & (~moo | (~d1[COLS:1] & ~d2[COLS-1:0])));
    // N's partial mask (earlier neighbours: left strict, the row above), of w0_q's row
    wire [COLS-1:0] part_c = ct_q & cl[COLS-1:0] & ~cl[COLS:1] & (cu | {COLS{t3_q}});

    // ---- serialiser: the maxima of the window's row, lowest column first ---------------------
    reg [COLS-1:0]      rem_q;                 // w1_q's partial mask, less the maxima taken
    (* fsm_encoding = "none" *)
    reg [ROW_IDX_W-1:0] mrow_q;                // row of w1_q
    // the maxima of w1_q not yet taken: its partial mask (rem_q, loaded when the window
    // shifts it into w1_q) AND its test against the row below (dm, of the registers
    // loaded then too)
    wire [COLS-1:0] rem_e   = rem_q & dm;
    wire [COLS-1:0] rem_m1  = rem_e - 1'b1;
    wire [COLS-1:0] rem_low = rem_e & ~rem_m1;   // its lowest maximum, one-hot
    wire [COLS-1:0] rem_nx  = rem_e & rem_m1;    // the others
    // rem_q holds two bits or more (a balanced tree of 4-bit groups: any, two or more;
    // rem_q's own bits only, not rem_e: no mask gates and no carry chain before adv)
    localparam NT1 = (COLS + 3) / 4;           // 4-bit groups
    localparam NT2 = (NT1 + 3) / 4;            // groups of 4 groups
    wire [4*NT1-1:0] two_r = {{(4*NT1 - COLS){1'b0}}, rem_q};
    wire [4*NT2-1:0] t1_a, t1_t;               // level 1: any, two or more (padded)
    wire [4*NT2-1:0] t2_a, t2_t;               // level 2
    genvar gt;
    generate
        for (gt = 0; gt < 4 * NT2; gt = gt + 1) begin : g_two1
            if (gt < NT1) begin : g_v
                wire [3:0] b = two_r[4*gt +: 4];
                assign t1_a[gt] = |b;
                assign t1_t[gt] = (b[0] & (b[1] | b[2] | b[3])) | (b[1] & (b[2] | b[3])) | (b[2] & b[3]);
            end else begin : g_z
                assign t1_a[gt] = 1'b0;
                assign t1_t[gt] = 1'b0;
            end
        end
        for (gt = 0; gt < 4 * NT2; gt = gt + 1) begin : g_two2
            if (gt < NT2) begin : g_v
                wire [3:0] a = t1_a[4*gt +: 4];
                assign t2_a[gt] = |a;
                assign t2_t[gt] = (|t1_t[4*gt +: 4])
                                | (a[0] & (a[1] | a[2] | a[3])) | (a[1] & (a[2] | a[3])) | (a[2] & a[3]);
            end else begin : g_z
                assign t2_a[gt] = 1'b0;
                assign t2_t[gt] = 1'b0;
            end
        end
    endgenerate
    // level 3: pairs of the NT2 groups
    reg rem_two;
    /* verilator lint_off UNUSEDSIGNAL */     // integer temporaries: their low bits are used
    always @(*) begin : c_two
        integer i, j;
        rem_two = 1'b0;
        for (i = 0; i < NT2; i = i + 1) begin
            rem_two = rem_two | t2_t[i];
            for (j = i + 1; j < NT2; j = j + 1)
                rem_two = rem_two | (t2_a[i] & t2_a[j]);
        end
    end
    /* verilator lint_on UNUSEDSIGNAL */
    // adv's next value: rem_q holds at most one bit (so rem_q's next value is 0), and no
    // finishing step with a partial mask (a superset of its final mask: the stall for a
    // row whose maxima the row below all removes is one cycle, with no capture).  In the
    // first serialising cycle of a row rem_q is its partial mask, not yet ANDed with the
    // down mask: a row with two partial-mask cells or more and at most one maximum holds
    // the window one cycle more (two cycles; the last one takes nothing)
    wire            adv_d   = rst || (advs_q ? !(v2_q && f2_q && (|part_c)) : !rem_two);
    // the window shifts next cycle: adv then, and a step in s2 then
    wire            wsh_d   = !rst && adv_d && (advs_q ? v1_q : v2_q);

    // the enable copies (keep: one flip-flop each, not merged by synthesis)
    (* keep *) always @(posedge clk) advc_q <= adv_d;
    (* keep *) always @(posedge clk) advs_q <= adv_d;
    (* keep *) always @(posedge clk) advr_q <= adv_d;
    genvar gk;
    generate
        for (gk = 0; gk < NOC; gk = gk + 1) begin : g_advo
            (* keep *) always @(posedge clk) advo_q[gk] <= adv_d;
        end
        for (gk = 0; gk < NWC; gk = gk + 1) begin : g_wsh
            (* keep *) always @(posedge clk) wsh_q[gk] <= wsh_d;
        end
    endgenerate

    // the output register (N) and the window, per column, enabled by their group's copy
    generate
        for (gk = 0; gk < COLS; gk = gk + 1) begin : g_win
            always @(posedge clk) begin
                if (advo_q[(gk * NOC) / COLS])
                    do_q[gk*HM_W +: HM_W] <= rd_q[gk*HM_W +: HM_W];
                if (wsh_q[(gk * NWC) / COLS]) begin
                    w0_q[gk*HM_W +: HM_W] <= do_q[gk*HM_W +: HM_W];
                    w1_q[gk*HM_W +: HM_W] <= w0_q[gk*HM_W +: HM_W];
                    w2_q[gk*HM_W +: HM_W] <= w1_q[gk*HM_W +: HM_W];
                    cl_q[gk]              <= gtl[gk];
                    ct_q[gk]              <= thr_n[gk];
                    cg_q[gk]              <= gtv[gk];
                end
            end
            if (gk > 0) begin : g_d
                always @(posedge clk)
                    if (wsh_q[(gk * NWC) / COLS]) begin
                        g1_q[gk] <= gd1[gk];
                        g2_q[gk] <= gd2[gk];
                    end
            end
        end
    endgenerate

    // The serialiser's lowest maximum, one-hot, registered (low_q: loaded in every cycle,
    // used when iv_q is set): its column index, quotient and remainder by 3 and the
    // capture's selects are decoded from it in the next cycle, each into registers of
    // its own, so no encoder output fans out to select copies.
    reg  [COLS-1:0] low_q;
    // column index, its quotient and remainder by 3, as ORs of the one-hot bits of low_q
    localparam NPC  = COLS + 2;
    localparam NGR  = (NPC + 2) / 3;
    localparam QI_W = $clog2(NGR + 1);
    localparam NGA  = 1 << QI_W;
    reg [COL_IDX_W-1:0] lo_col;
    reg [QI_W-1:0]      lo_q, lo_g0, lo_g1;    // col / 3; the group 0 and 1 cells (below)
    reg [1:0]           lo_m;
    /* verilator lint_off UNUSEDSIGNAL */     // integer temporaries: their low bits are used
    always @(*) begin : c_lo
        integer i, qd, md, g0, g1;
        qd     = 0;
        md     = 0;
        g0     = 0;
        g1     = 0;
        lo_col = {COL_IDX_W{1'b0}};
        lo_q   = {QI_W{1'b0}};
        lo_g0  = {QI_W{1'b0}};
        lo_g1  = {QI_W{1'b0}};
        lo_m   = 2'd0;
        for (i = 0; i < COLS; i = i + 1)
            if (low_q[i]) begin
                qd     = i / 3;
                md     = i % 3;
                lo_col = lo_col | i[COL_IDX_W-1:0];
                lo_q   = lo_q   | qd[QI_W-1:0];
                lo_m   = lo_m   | md[1:0];
                g0     = qd + ((md > 0) ? 1 : 0);
                g1     = qd + ((md > 1) ? 1 : 0);
                lo_g0  = lo_g0  | g0[QI_W-1:0];
                lo_g1  = lo_g1  | g1[QI_W-1:0];
            end
    end
    /* verilator lint_on UNUSEDSIGNAL */

    reg                 iv_q;                  // a maximum to capture
    // The capture selects a cell of each group in two registered steps: one cell in each
    // quarter of the group (NQ quarters of NL cells), by its number within the quarter
    // decoded from the low_q bits of the quarter's columns (a select local to the
    // quarter's columns), then the quarter, by the high HI_W bits of the cell number
    // decoded from low_q.  (Before:
    // the select bits encoded from the lowest bit and registered in copies per quarter,
    // the encoder's fan-out to the copies critical at 84.1 MHz.)
    localparam LO_W = (QI_W > 2) ? 2 : 1;
    localparam HI_W = QI_W - LO_W;
    localparam NL   = 1 << LO_W;
    localparam NQ   = 1 << HI_W;

    // ---- capture: the 3x3 of the maximum from the window ----------------------------------
    // The three rows padded with a zero cell at each end (padded cell p = column p - 1);
    // the maximum's window is padded cells p0 .. p0 + 2, p0 = the maximum's column.  The
    // padded cells are split by p mod 3 into three groups of NGR cells (cell j of group g
    // is p = 3j + g, 0 beyond the row): the window holds exactly one cell of each group, cell q or q + 1
    // (q = p0 / 3, m = p0 mod 3: q + 1 for the groups g < m), and window position k takes
    // group (m + k) mod 3.  Three NGR : 1 selects and a 3 : 1 rotation per row and bit
    // instead of three (COLS + 2) : 1 selects.
    wire [HM_W-1:0] ga0 [0:NGA-1], ga1 [0:NGA-1], ga2 [0:NGA-1];
    wire [HM_W-1:0] gb0 [0:NGA-1], gb1 [0:NGA-1], gb2 [0:NGA-1];
    wire [HM_W-1:0] gc0 [0:NGA-1], gc1 [0:NGA-1], gc2 [0:NGA-1];
    genvar gj;
    generate
        for (gj = 0; gj < NGA; gj = gj + 1) begin : g_grp
            // padded cell 3j + g is column 3j + g - 1; a: row above, b: the row, c: below
            if (3 * gj >= 1 && 3 * gj <= COLS) begin : g_0
                assign ga0[gj] = w2_q[(3*gj-1)*HM_W +: HM_W];
                assign gb0[gj] = w1_q[(3*gj-1)*HM_W +: HM_W];
                assign gc0[gj] = w0_q[(3*gj-1)*HM_W +: HM_W];
            end else begin : g_0z
                assign ga0[gj] = {HM_W{1'b0}};
                assign gb0[gj] = {HM_W{1'b0}};
                assign gc0[gj] = {HM_W{1'b0}};
            end
            if (3 * gj + 1 <= COLS) begin : g_1
                assign ga1[gj] = w2_q[(3*gj)*HM_W +: HM_W];
                assign gb1[gj] = w1_q[(3*gj)*HM_W +: HM_W];
                assign gc1[gj] = w0_q[(3*gj)*HM_W +: HM_W];
            end else begin : g_1z
                assign ga1[gj] = {HM_W{1'b0}};
                assign gb1[gj] = {HM_W{1'b0}};
                assign gc1[gj] = {HM_W{1'b0}};
            end
            if (3 * gj + 2 <= COLS) begin : g_2
                assign ga2[gj] = w2_q[(3*gj+1)*HM_W +: HM_W];
                assign gb2[gj] = w1_q[(3*gj+1)*HM_W +: HM_W];
                assign gc2[gj] = w0_q[(3*gj+1)*HM_W +: HM_W];
            end else begin : g_2z
                assign ga2[gj] = {HM_W{1'b0}};
                assign gb2[gj] = {HM_W{1'b0}};
                assign gc2[gj] = {HM_W{1'b0}};
            end
        end
    endgenerate
    // capture step 1: per quarter, the cells of the nine groups (rows a, b, c; groups 0,
    // 1, 2) at the low select bits, registered (s1_q, quarter h at [h*Z9_W +: Z9_W],
    // group order as pz_q)
    wire [NQ*Z9_W-1:0] s1_q;
    genvar gq;
    generate
        for (gq = 0; gq < NQ; gq = gq + 1) begin : g_quarter
            // cell j of group g is in the window of the columns 3j + g - 2 .. 3j + g: its
            // number within the quarter, from the low_q bits of the quarter's columns (0
            // when the maximum is in another quarter: step 2 does not pick this one)
            reg [LO_W-1:0] l0, l1, l2;         // group 0, 1, 2 cell, low bits
            reg [Z9_W-1:0] s_q;
            /* verilator lint_off UNUSEDSIGNAL */     // integer temporaries: their low bits are used
            always @(*) begin : c_sel
                integer i, j0, j1, j2;
                l0 = {LO_W{1'b0}};  l1 = {LO_W{1'b0}};  l2 = {LO_W{1'b0}};
                for (i = 0; i < COLS; i = i + 1) begin
                    j0 = (i + 2) / 3;  j1 = (i + 1) / 3;  j2 = i / 3;
                    if (j0 / NL == gq) l0 = l0 | ({LO_W{low_q[i]}} & j0[LO_W-1:0]);
                    if (j1 / NL == gq) l1 = l1 | ({LO_W{low_q[i]}} & j1[LO_W-1:0]);
                    if (j2 / NL == gq) l2 = l2 | ({LO_W{low_q[i]}} & j2[LO_W-1:0]);
                end
            end
            /* verilator lint_on UNUSEDSIGNAL */
            always @(posedge clk)
                s_q <= {gc2[gq*NL + l2], gc1[gq*NL + l1], gc0[gq*NL + l0],
                        gb2[gq*NL + l2], gb1[gq*NL + l1], gb0[gq*NL + l0],
                        ga2[gq*NL + l2], ga1[gq*NL + l1], ga0[gq*NL + l0]};
            assign s1_q[gq*Z9_W +: Z9_W] = s_q;
        end
    endgenerate
    reg             p1v_q;                     // capture step 1 valid
    (* fsm_encoding = "none" *)             // (Yosys would extract them as FSMs)
    reg [HI_W-1:0]  p1h0_q, p1h1_q, p1h2_q;    // the quarters of groups 0, 1, 2
    (* fsm_encoding = "none" *)
    reg [1:0]       p1m_q;
    reg             p1top_q, p1bot_q;
    reg [IDX_W-1:0] p1idx_q;
    // capture step 2: the quarter of each group
    reg [Z9_W-1:0]  s2;
    /* verilator lint_off UNUSEDSIGNAL */     // integer temporaries: their low bits are used
    always @(*) begin : c_s2
        integer h, r;
        s2 = {Z9_W{1'b0}};
        for (h = 0; h < NQ; h = h + 1)
            for (r = 0; r < 3; r = r + 1) begin
                if (p1h0_q == h[HI_W-1:0]) s2[(3*r+0)*HM_W +: HM_W] = s1_q[h*Z9_W + (3*r+0)*HM_W +: HM_W];
                if (p1h1_q == h[HI_W-1:0]) s2[(3*r+1)*HM_W +: HM_W] = s1_q[h*Z9_W + (3*r+1)*HM_W +: HM_W];
                if (p1h2_q == h[HI_W-1:0]) s2[(3*r+2)*HM_W +: HM_W] = s1_q[h*Z9_W + (3*r+2)*HM_W +: HM_W];
            end
    end
    /* verilator lint_on UNUSEDSIGNAL */
    reg             pv_q;                      // pre-capture valid
    reg [Z9_W-1:0]  pz_q;                      // the nine cells, group order
    reg [1:0]       pm_q;                      // their rotation (column mod 3)
    reg             ptop_q, pbot_q;            // first / last row
    reg [IDX_W-1:0] pidx_q;                    // raster index
    // the centre cell (= z9's centre below) in registers of its own: the list's early
    // compare does not wait on the rotation; in NLC copies (keep), each for K / NLC of
    // the list's comparators (no one register drives all K)
    localparam NLC = (K >= 4) ? 4 : 1;
    reg  [NLC*HM_W-1:0] pc_q;
    reg  [HM_W-1:0]     pc_d;
    always @(*) begin
        case (p1m_q)                           // z9's centre (row b, rotated)
            2'd1:    pc_d = s2[5*HM_W +: HM_W];
            2'd2:    pc_d = s2[3*HM_W +: HM_W];
            default: pc_d = s2[4*HM_W +: HM_W];
        endcase
    end
    genvar gpc;
    generate
        for (gpc = 0; gpc < NLC; gpc = gpc + 1) begin : g_pc
            (* keep *) always @(posedge clk) pc_q[gpc*HM_W +: HM_W] <= pc_d;
        end
    endgenerate
    // continuing-maximum flag of the maximum in pidx_q (the block "continuing maxima"
    // below), in NLC copies beside pc_q's, and of the captured one
    reg  [NLC-1:0]      nearp_q;
    reg                 cap_near_q;
    wire                near_d;
    wire [NLC*KEY_W-1:0] nxt_key;              // the list's early keys {near, centre}
    genvar gnk;
    generate
        for (gnk = 0; gnk < NLC; gnk = gnk + 1) begin : g_nk
            (* keep *) always @(posedge clk) nearp_q[gnk] <= near_d;
            assign nxt_key[gnk*KEY_W +: KEY_W] = {nearp_q[gnk], pc_q[gnk*HM_W +: HM_W]};
        end
    endgenerate
    wire [HM_W-1:0] qa0 = pz_q[0*HM_W +: HM_W], qa1 = pz_q[1*HM_W +: HM_W], qa2 = pz_q[2*HM_W +: HM_W];
    wire [HM_W-1:0] qb0 = pz_q[3*HM_W +: HM_W], qb1 = pz_q[4*HM_W +: HM_W], qb2 = pz_q[5*HM_W +: HM_W];
    wire [HM_W-1:0] qc0 = pz_q[6*HM_W +: HM_W], qc1 = pz_q[7*HM_W +: HM_W], qc2 = pz_q[8*HM_W +: HM_W];
    reg [Z9_W-1:0] z9;
    always @(*) begin
        case (pm_q)
            2'd1:    z9 = {qc0, qc2, qc1, qb0, qb2, qb1, qa0, qa2, qa1};
            2'd2:    z9 = {qc1, qc0, qc2, qb1, qb0, qb2, qa1, qa0, qa2};
            default: z9 = {qc2, qc1, qc0, qb2, qb1, qb0, qa2, qa1, qa0};
        endcase
        if (ptop_q) z9[0 +: 3*HM_W]      = {(3*HM_W){1'b0}};
        if (pbot_q) z9[6*HM_W +: 3*HM_W] = {(3*HM_W){1'b0}};
    end
    reg              cap_v_q;                  // one maximum captured
    reg [Z9_W-1:0]   cap_z_q;                  // its 3x3
    reg [IDX_W-1:0]  cap_idx_q;                // its raster index {row, col}

    // ---- the sorted list of (z, raster index), payload = slot of the 3x3 store --------------
    wire releasing;
    reg [FOUND_W-1:0] found_q;
    reg [LIM_W-1:0]   left_q;                  // candidates still to emit
    wire              em_issue = (state_q == S_EMIT) && (left_q != {LIM_W{1'b0}});
    /* verilator lint_off UNUSEDSIGNAL */      // entry 0's index and slot only are read
    wire [K-1:0]        l_v;
    wire [K*KEY_W-1:0]  l_z;
    wire [K*IDX_W-1:0]  l_idx;                 // raster index {row, col} of entry i
    wire [K*SLOT_W-1:0] l_slot;                // 3x3 store slot of entry i
    /* verilator lint_on UNUSEDSIGNAL */
    wire [SLOT_W-1:0]   l_free;                // the slot out of the list (next insert's)
    // the list compares a cycle early: cap_z_q's centre and cap_idx_q take z9's centre
    // (= each copy of pc_q) and pidx_q in every cycle
    fmt_sorted_list #(.K(K), .KEY_W(KEY_W), .TIE_W(IDX_W), .PAY_W(SLOT_W), .PAY_RST_IDX(1),
                      .HAS_POP(1), .EARLY(1), .NXT_CP(NLC)) u_list (
        .clk(clk), .rst(rst), .clear_i(releasing),
        .ins_i(cap_v_q), .ins_key_i({cap_near_q, cap_z_q[4*HM_W +: HM_W]}), .ins_tie_i(cap_idx_q),
        .nxt_key_i(nxt_key), .nxt_tie_i(pidx_q), .ins_ahead_i(1'b0),
        .ins_pay_i(l_free),
        .pop_i(em_issue), .valid_o(l_v), .key_o(l_z), .tie_o(l_idx), .pay_o(l_slot),
        .drop_pay_o(l_free));

    // 3x3 store: K + 1 slots, written with the insert at the free slot
    (* ram_style = "block" *)
    reg [Z9_W-1:0] z9_mem [0:K];
    reg [Z9_W-1:0] z9_rd_q;                    // read register
    always @(posedge clk) begin
        if (cap_v_q) z9_mem[l_free] <= cap_z_q;
        if (em_issue) z9_rd_q <= z9_mem[l_slot[0 +: SLOT_W]];
    end

    // ---- emission ---------------------------------------------------------------------------
    wire [ROW_IDX_W-1:0] l_row0 = l_idx[COL_IDX_W +: ROW_IDX_W];
    wire [COL_IDX_W-1:0] l_col0 = l_idx[0 +: COL_IDX_W];
    reg                 em_v_q, em_eof_q;
    reg [ROW_IDX_W-1:0] em_row_q;
    reg [COL_IDX_W-1:0] em_col_q;
    reg [FRAME_W-1:0]   em_frame_q;
    reg [8:0]           miss9;
    always @(*) begin
        miss9 = 9'd0;
        if (em_col_q == {COL_IDX_W{1'b0}})     miss9 = miss9 | 9'b001_001_001;
        if (em_col_q == LAST_COL)              miss9 = miss9 | 9'b100_100_100;
        if (em_row_q == {ROW_IDX_W{1'b0}})     miss9 = miss9 | 9'b000_000_111;
        if (em_row_q == LAST_ROW)              miss9 = miss9 | 9'b111_000_000;
    end

    // ---- continuing maxima (issue #11 item 3: hysteresis on the ranking) ---------------------
    // The candidates the previous frame emitted, recorded as they are emitted (entry 0 the
    // latest; cleared at the finish, so none after a reset or an incomplete frame; the
    // next frame's sweep starts after the emission).  A maximum within one cell of one of
    // them (|row - r| <= 1 and |col - c| <= 1) is continuing: key {1, z}, ahead of every
    // new maximum.  The row test is made when the window shifts (w1_q's row, mrow_q's next
    // value, against every entry: rowhit_q), the column test in capture step 1 on
    // p1idx_q's column with rowhit_q's copy p1rh_q, registered in nearp_q beside pidx_q.
    reg [K-1:0]           pe_v_q;              // entry k valid
    reg [K*ROW_IDX_W-1:0] pe_r_q;              // its row
    reg [K*COL_IDX_W-1:0] pe_c_q;              // its column
    reg [K-1:0]           rowhit_q;            // entry k valid and within one row of mrow_q
    reg [K-1:0]           p1rh_q;              // rowhit_q of p1idx_q's row
    // the shift on an emission (the oldest entry's bits fall off the top)
    /* verilator lint_off UNUSEDSIGNAL */
    wire [K:0]            pe_v_sh = {pe_v_q, 1'b1};
    wire [K*ROW_IDX_W+ROW_IDX_W-1:0] pe_r_sh = {pe_r_q, l_row0};
    wire [K*COL_IDX_W+COL_IDX_W-1:0] pe_c_sh = {pe_c_q, l_col0};
    /* verilator lint_on UNUSEDSIGNAL */
    // a and b within one of each other (one bit wider: no wrap at the index's end)
    localparam NW = ((ROW_IDX_W > COL_IDX_W) ? ROW_IDX_W : COL_IDX_W) + 1;
    function near1;
        input [NW-1:0] a, b;
        near1 = (a == b) || (a == b + 1'b1) || (a + 1'b1 == b);
    endfunction
    reg [K-1:0] rowhit_d;
    reg         near_c;
    always @(*) begin : c_near
        integer k;
        near_c = 1'b0;
        for (k = 0; k < K; k = k + 1) begin
            rowhit_d[k] = pe_v_q[k]
                && near1({{(NW - ROW_IDX_W){1'b0}}, r2_q},
                         {{(NW - ROW_IDX_W){1'b0}}, pe_r_q[k*ROW_IDX_W +: ROW_IDX_W]});
            near_c = near_c | (p1rh_q[k] && near1({{(NW - COL_IDX_W){1'b0}}, p1idx_q[0 +: COL_IDX_W]},
                                                  {{(NW - COL_IDX_W){1'b0}}, pe_c_q[k*COL_IDX_W +: COL_IDX_W]}));
        end
    end
    assign near_d = near_c;

    // the limit and the counts of the finish, registered: limit_p a cycle old, found_q
    // one (it does not change in the cycle before finish: fin_pre_q waits for no capture)
    wire [LIM_W-1:0] lim_eff  = (limit_p > K_L) ? K_L : limit_p;
    reg  [LIM_W-1:0] lim_q;
    wire [FOUND_W-1:0] lim_ext = {{(FOUND_W > LIM_W ? FOUND_W - LIM_W : 0){1'b0}}, lim_q};
    wire             over_d   = (found_q > lim_ext);
    reg              over_q;                   // found_q > the limit
    reg  [LIM_W-1:0] n_emit_q;                 // candidates to emit
    reg  [FOUND_W-1:0] dropped_q;              // found_q - n_emit_q
    wire             complete = (arr_p == {ROWS{1'b1}});
    // finish: the frame's eof seen, no row ready, nothing in flight -- registered (one
    // cycle old: nothing can start in between, as no row was ready)
    reg              fin_pre_q;
    wire             finish   = run && fin_pre_q;
    assign           releasing = (state_q == S_EMIT) && (left_q == {LIM_W{1'b0}});
    wire [CNT_W:0]   drop_sum = {1'b0, drop_count_o} + {{(CNT_W + 1 - FOUND_W){1'b0}}, dropped_q};

    // the next values of arrp_q and done_q (reset aside) and the ready flags of them
    wire [ROWS-1:0] arrp_d = releasing         // pb_q flips; arr_p clears
                           ? ((pb_q ? arr0_q : arr1_q) | ((wb_q != pb_q) ? hm_1h : {ROWS{1'b0}}))
                           : (arrp_q | ((wb_q == pb_q) ? hm_1h : {ROWS{1'b0}}));
    wire [ROWS-1:0] done_d = releasing ? {ROWS{1'b0}}
                           : (done_q | ((issue && rule_a) ? cur1h_q : {ROWS{1'b0}}));
    reg  [ROWS-1:0] ready_d;
    always @(*) begin : c_ready_d
        integer i;
        for (i = 0; i < ROWS; i = i + 1)
            ready_d[i] = arrp_d[i] & ~done_d[i]
                       & ((i == 0)        ? 1'b1 : arrp_d[(i == 0) ? 0 : i - 1])
                       & ((i == ROWS - 1) ? 1'b1 : arrp_d[(i == ROWS - 1) ? i : i + 1]);
    end

    always @(posedge clk) begin
        // ---- datapath registers (no reset needed) ----
        lim_q     <= lim_eff;
        over_q    <= over_d;
        n_emit_q  <= over_d ? lim_q : found_q[LIM_W-1:0];
        dropped_q <= over_d ? found_q - lim_ext : {FOUND_W{1'b0}};
        jx_q     <= jx_d;
        jx1h_q   <= jx1h_d;
        jx0_q    <= rdy_low[0] | rdy_low[1];
        if (adv) begin
            a0_q <= {pb_q, x_row};
            r0_q <= cur_q;
            t0_q <= !(rule_a || rule_b) && jx0_q;
            x0_q <= rule_a && last_c;
            f0_q <= rule_a;
            r1_q <= r0_q;  t1_q <= t0_q;  x1_q <= x0_q;  f1_q <= f0_q;
            r2_q <= r1_q;  t2_q <= t1_q;  x2_q <= x1_q;  f2_q <= f1_q;
            if (v2_q) begin                    // the window shifts
                t3_q   <= t2_q;
                mrow_q <= r2_q;
                rowhit_q <= rowhit_d;
                mtop_q <= (r2_q == {ROW_IDX_W{1'b0}});
                mbot_q <= x2_q;
            end
        end
        low_q     <= rem_low;
        p1h0_q    <= lo_g0[QI_W-1:LO_W];
        p1h1_q    <= lo_g1[QI_W-1:LO_W];
        p1h2_q    <= lo_q[QI_W-1:LO_W];
        p1m_q     <= lo_m;
        p1top_q   <= mtop_q;
        p1bot_q   <= mbot_q;
        p1idx_q   <= {mrow_q, lo_col};
        p1rh_q    <= rowhit_q;
        pz_q      <= s2;
        pm_q      <= p1m_q;
        ptop_q    <= p1top_q;
        pbot_q    <= p1bot_q;
        pidx_q    <= p1idx_q;
        cap_z_q   <= z9;
        cap_idx_q <= pidx_q;
        cap_near_q <= nearp_q[0];
        cand_z_o       <= z9_rd_q;
        cand_missing_o <= miss9;
        cand_row_o     <= em_row_q;
        cand_col_o     <= em_col_q;
        cand_frame_o   <= em_frame_q;

        if (rst) begin
            arr0_q   <= {ROWS{1'b0}};
            arr1_q   <= {ROWS{1'b0}};
            eofs_q   <= 2'b00;
            wb_q     <= 1'b0;
            pb_q     <= 1'b0;
            done_q   <= {ROWS{1'b0}};
            cur_q    <= {ROW_IDX_W{1'b0}};
            cv_q     <= 1'b0;
            cp_q     <= 1'b0;
            rule_c_q <= 1'b0;
            arrp_q   <= {ROWS{1'b0}};
            rdy_q    <= {ROWS{1'b0}};
            rule_a_q <= 1'b0;
            rule_b_q <= 1'b0;
            state_q  <= S_RUN;
            v0_q     <= 1'b0;
            v1_q     <= 1'b0;
            v2_q     <= 1'b0;
            rem_q    <= {COLS{1'b0}};
            iv_q     <= 1'b0;
            cap_v_q  <= 1'b0;
            p1v_q    <= 1'b0;
            pv_q     <= 1'b0;
            fin_pre_q <= 1'b0;
            found_q  <= {FOUND_W{1'b0}};
            left_q   <= {LIM_W{1'b0}};
            em_v_q   <= 1'b0;
            em_eof_q <= 1'b0;
            em_row_q <= {ROW_IDX_W{1'b0}};
            em_col_q <= {COL_IDX_W{1'b0}};
            pe_v_q   <= {K{1'b0}};
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
            if (hm_valid_i) begin
                if (wb_q) arr1_q[hm_row_i] <= 1'b1;
                else      arr0_q[hm_row_i] <= 1'b1;
            end
            arrp_q <= arrp_d;
            done_q <= done_d;
            rdy_q  <= ready_d;
            if (hm_eof_i) begin
                eofs_q[wb_q] <= 1'b1;
                if (wb_q) frm1_q <= hm_frame_i;
                else      frm0_q <= hm_frame_i;
                wb_q         <= ~wb_q;
                // the other buffer still holds an unfinished frame: it will be overwritten
                if (pb_q != wb_q && !releasing) overrun_o <= 1'b1;
            end

            // ---- sweep ----
            // rule c of the next cycle: the lowest ready row j (not finished: ready), unless
            // the step now finishes it (j = cur)
            rule_c_q <= (|ready) && !(issue && rule_a && (|(rdy_low & cur1h_q)));
            if (adv) begin
                v0_q <= issue;
                v1_q <= v0_q;
                v2_q <= v1_q;
            end
            // rules a and b of the next cycle (cv, cp and cur1h_q as the step leaves them)
            if (issue) begin
                rule_a_q <= !vstep && (ab ? a_up : (jx0_q && a_jump));
                rule_b_q <= !vstep && (ab ? b_up : b_jump);
            end else begin
                rule_a_q <= cv_q && cp_q && a_hold;
                rule_b_q <= cv_q && b_hold;
            end
            if (issue) begin
                if (rule_a && last_c) begin
                    cv_q <= 1'b0;                      // virtual step after the last row
                end else begin
                    cv_q    <= 1'b1;
                    cur_q   <= x_row;
                    cur1h_q <= (rule_a || rule_b) ? (cur1h_q << 1) : jx1h_q;
                    cp_q    <= (rule_a || rule_b) || jx0_q;
                end
            end

            // ---- serialiser ----
            if (!advs_q) begin                 // rem_e != 0, or one stall cycle with rem_e = 0
                rem_q <= rem_nx;
                iv_q  <= |rem_e;
            end else begin
                iv_q  <= 1'b0;
                if (v2_q && f2_q) rem_q <= part_c;   // rem_q = 0 here (advs_q): a new row
            end
            p1v_q   <= iv_q;
            pv_q    <= p1v_q;
            cap_v_q <= pv_q;
            if (cap_v_q) found_q <= found_q + 1'b1;

            // ---- finish and emit ----
            fin_pre_q <= run && eofs_q[pb_q] && !(|ready) && !v0_q && !v1_q && !v2_q && adv
                      && !iv_q && !p1v_q && !pv_q && !cap_v_q;
            if (finish) begin
                state_q    <= S_EMIT;
                pe_v_q     <= {K{1'b0}};        // this frame's candidates replace the last's
                em_frame_q <= pb_q ? frm1_q : frm0_q;
                left_q     <= complete ? n_emit_q : {LIM_W{1'b0}};
                cand_count_o      <= complete ? n_emit_q : {LIM_W{1'b0}};
                cand_found_o      <= complete ? found_q : {FOUND_W{1'b0}};
                cand_overflow_o   <= complete && over_q;
                cand_incomplete_o <= !complete;
                if (complete && over_q) begin
                    overflow_flag_o <= 1'b1;
                    drop_count_o    <= drop_sum[CNT_W] ? {CNT_W{1'b1}} : drop_sum[CNT_W-1:0];
                end
            end
            // emission: em_issue pops entry 0 and reads its 3x3 (block RAM), then the
            // output registers; cand_eof follows the last candidate
            em_v_q       <= em_issue;
            em_eof_q     <= releasing;
            cand_valid_o <= em_v_q;
            cand_eof_o   <= em_eof_q;
            if (em_issue) begin
                em_row_q <= l_row0;
                em_col_q <= l_col0;
                left_q   <= left_q - 1'b1;      // the list pops entry 0
                pe_v_q   <= pe_v_sh[K-1:0];     // recorded for the next frame's ranking
                pe_r_q   <= pe_r_sh[K*ROW_IDX_W-1:0];
                pe_c_q   <= pe_c_sh[K*COL_IDX_W-1:0];
            end
            if (releasing) begin
                state_q      <= S_RUN;      // the list is cleared
                found_q      <= {FOUND_W{1'b0}};
                cv_q         <= 1'b0;
                rule_a_q     <= 1'b0;
                rule_b_q     <= 1'b0;
                if (pb_q) arr1_q <= {ROWS{1'b0}};
                else      arr0_q <= {ROWS{1'b0}};
                eofs_q[pb_q] <= 1'b0;
                pb_q         <= ~pb_q;
            end
        end
    end

endmodule

`default_nettype wire
