// fmt_blob -- blob detection: 4-connected regions of z >= blob_threshold_i with at least
// blob_min_cells_i cells, streamed out largest first (twin: sim/fmt/blob.py,
// blob_stream_fixed).
//
// Heat-map stream in (docs/ARCHITECTURE.md): rows in ANY order, one per cycle at most,
// stored in an inferred block RAM of 2 x ROWS words of COLS*HM_W bits (two frame
// buffers, as in fmt_localmax), and their on-cells (z >= blob_threshold_i as the row
// arrives) in a LUT RAM (on_mem).  The frame is labelled in raster order as soon as a
// prefix of rows is present:
//   F1, F2: fetch the next row (block-RAM read and output register) and its on-cells C;
//       the fetch is decided from registers (av_q: the next row is present, registered
//       from its next value), the block RAM is one memory per 8 columns, and the wide
//       enables of the block RAMs, F2 and E are per 8 columns from kept copies;
//       against the previous row's on-cells P (A = C & P) the row's events are found:
//       each C run gives a RUN event at its first column, with its first A column
//       (found by one addition: the carry from the run's start runs through its C-only
//       cells and lands on the first A cell); each further A run inside the C run gives
//       a MERGE event at its first column.  Two events are never on adjacent columns,
//       so a row has at most ceil(COLS/2) events (a row without any: one empty event).
//   E : one event per cycle (lowest remaining event column, one carry chain), the C
//       run's columns for a RUN event.
//   X1..X5: the run's sums: X2 the masked cells' sums per 8-column group and the
//       extent; X3 sum z over the groups and the groups' sums z*(c mod 8) (balanced
//       trees) and T = sum g * (group g's sum z); X4 sum z*c = that sum + 8 T and the
//       two halves of sum z*r = r * sum z (shift
//       and add); X5 sum z*r.  The peak and its first column by a tournament of 1, 2,
//       2, 1 levels in X2..X5.  Then the event enters a 32-entry FIFO (LUT RAM).  The
//       extraction runs ahead of the labelling by up to the FIFO depth.
//   L0, LG, L1: the label under the event's label column: L0 selects it, per 8 columns,
//       from the previous row's labels P (one per column, 0 = background), or from the
//       current row's labels C when the step in L2 may end the previous row first
//       (registered per group); the step of that cycle is registered (its victim,
//       survivor, run label) and applied in LG, which gathers the groups; the step of
//       LG's cycle is applied in L1, together with the step of L1's own cycle (its
//       rename, its run).
//   L2: one step per cycle (x = the label of the current C run, y = L1's label):
//         RUN, a label y        -> ADD(y): the C run's columns in C get y, x = y
//         RUN, no label         -> NEW(n): n = a free label (prefetched), x = n
//         MERGE, y != x         -> MERGE(x <- y): y is renamed x in P, C and alias; y is
//                                  free again
//       The step's controls are registers: a merge is decided when L2 loads its event
//       (a merge never waits in L2), the step, its run and the row end from their next
//       values; they, x and y have copies per 8 columns of P and C, per alias group and
//       for the label masks (the wide renames take no high-fanout net).
//       The row's last event ends it: the labels of P no longer in C are closed (their
//       region is complete), P = C; after the last row every live label is closed.
//       Labels are slots 1..NL, NL = 2*ceil(COLS/2) + 12: P and C hold at most
//       ceil(COLS/2) labels each, and the labels closed at a row end plus the new
//       labels of the next row stay below that bound but for a few cycles of pipeline
//       (the close engine frees one label per cycle from 3 cycles after the row end;
//       one label is prefetched).  A NEW would wait for a free label (tb/fmt_blob checks
//       that it never does); nothing is ever dropped.
//   A : the command updates the per-label accumulators (LUT RAM, one write, two reads,
//       one of them shared with the close engine): NEW writes the run, ADD combines the
//       run, MERGE combines label y into x.  The reads are registered and the update
//       written one cycle later (W); an operand that the update of the cycle before
//       wrote is taken from that update's register.  (A closed label is read two
//       cycles after its last update at the earliest: the close timing is unchanged.)
//       The memory is split into five field slices (a field's update reads its own
//       slice only), each with its own read and write address registers, computed from
//       their next values, and its own copies of the controls.
//   C : the close engine takes one closed label per cycle (picked one cycle ahead):
//       if its area >= min_cells it is inserted into a sorted list of MAX_BLOBS entries
//       (fmt_sorted_list: area descending, ties by the raster index of the region's
//       first cell ascending); the smallest falls off.  The list holds the keys and a
//       slot number; the entries sit in LUT RAM.
// After the frame's hm_eof, once every row is labelled and every label closed, the list
// is emitted: centroid cx = (sum z*c * 256 + sum z / 2) / sum z (round half up, the
// same for cy): the entry's slot registered (EA), its sums read and the numerator
// registered (EB), then one pipelined fmt_div (QW + 1 cycles, QW = max index width + 8)
// shared by the coordinates (the n x quotients, then the n y quotients), one blob per cycle,
// then blob_eof_o (also for a frame without blobs).
//
// Membership (for removing the fingers inside blobs): the labelling stores the labels
// of every row at its end (lr_mem: the row's on-cells and, per column pair, the label
// of the run that starts in the pair, if any: a run's cells share its label, and two
// run starts are never adjacent); at the end of row r+1, for each label of row r,
// whether it continued into row r+1 and as which label (after the merges of row r+1)
// (fr_mem); and the close engine stores, per label and row r, whether the
// label closed at the end of row r was a blob (cf_mem: block RAM, a byte enable per
// label).  After the frame a pass from
// the last row up gives, one row per cycle, the status of every label of row r: the
// status of its continuation in row r+1 (known from the previous step) or, when it did
// not continue, its close record; one stage later every run start of the row gets its
// label's status, stored with the row's on-cells (mask_mem, LUT RAM, ROWS x 2 COLS
// bits); the query fills the runs whose start has status 1 by one addition (on + starts:
// the carry runs through the run), a row of the mask (every blob, also those beyond
// MAX_BLOBS: blobs.blob_mask_fixed).
// Query port: (mask_q_row_i, mask_q_col_i) -> the row's mask word (read and filled) one
// cycle later -> mask_q_data_o = the cell's bit two cycles after the address; one query per cycle,
// pipelined.  mask_ready_o
// (with mask_frame_o) marks the mask written; it stays readable until the next frame's
// pass starts (that frame is labelled; never before its last row), queries in between
// return 0.  An incomplete frame gives mask_ready_o with an all-zero mask.
//
// Fixed point: blob_cx_o, blob_cy_o are unsigned Q8.8 cells from the centre of cell
// (0, 0), zero-extended to 16 bits; exact (round half up of the exact rational).
// Sums are wide enough for a frame of saturated cells: nothing can overflow.
// blob_threshold_i must be >= 1 (sum z > 0); with 0 an all-zero region would divide
// by 0 (fmt_div then returns all ones) -- the model refuses threshold 0.
//
// Latency (processing-clock cycles, measured by tb/fmt_blob): a row is fetched as soon
// as rows 0..r are present; the extraction and the labelling take max(1, events)
// cycles per row each (no bubble between rows: L1 forwards the step of L2), the
// extraction ahead; from a row's fetch to its first step 13 cycles; after the last
// row's last step: 3 cycles to the close engine, one cycle per closed label, then the emission
// (QW + 5 + 2 x blobs cycles) and, in parallel, the membership pass (ROWS + 4).
// 30 x 40, rows in the FFT's order one per cycle, a palm: last row beat -> blob_eof_o
// 50..59 cycles, -> mask_ready_o 65..72 cycles.  Worst case per frame: at most
// ceil(COLS/2) events per row (600 at 30 x 40) plus the pipeline; measured from the
// first row beat to the end: checkerboard (600 RUN events, every label slot live) 693,
// combs 653, weave (the most merges with the most runs) 654 cycles: within the
// 768-cycle frame period at 3 x fs (python -m pytest -q -s tb/fmt_blob -k default;
// 2026-11-28: LG +1 cycle, EA/EB +2 cycles to blob_eof_o).  A frame must be finished (blob_eof_o and the
// membership pass) before the next frame's hm_eof, else overrun_o (sticky).
//
// Settings are taken with the rows: the threshold applies to a row when it arrives,
// min-cells (held per frame buffer) to the regions of the frame its rows arrived with;
// hold both constant over a frame's rows (fmt_touch does).
`default_nettype none
`include "fmt_defaults.vh"

module fmt_blob #(
    parameter ROWS      = `FMT_ROWS,            // heat-map rows
    parameter COLS      = `FMT_COLS,            // heat-map columns
    parameter HM_W      = `FMT_HM_W,            // cell width, unsigned
    parameter MAX_BLOBS = 8,                    // blob list length (blobs reported per frame)
    parameter FRAME_W   = 16,                   // frame number width
    parameter ROW_IDX_W = (ROWS > 1) ? $clog2(ROWS) : 1,    // row index width
    parameter COL_IDX_W = (COLS > 1) ? $clog2(COLS) : 1,    // column index width
    parameter AREA_W    = $clog2(ROWS * COLS + 1),          // area / min-cells / found width
    parameter CNT_W     = $clog2(MAX_BLOBS + 1),            // blob count width
    parameter MINC_W    = 16                                // blob_min_cells_i width
) (
    input  wire                   clk,
    input  wire                   rst,               // synchronous, active high
    // settings
    input  wire [HM_W-1:0]        blob_threshold_i,  // cell is "on" when z >= threshold (>= 1)
    input  wire [MINC_W-1:0]      blob_min_cells_i,  // region of >= this many cells is a blob
    // heat-map stream in
    input  wire                   hm_valid_i,        // one row this cycle
    input  wire [ROW_IDX_W-1:0]   hm_row_i,          // row index
    input  wire [FRAME_W-1:0]     hm_frame_i,        // frame number (taken with hm_eof_i)
    input  wire [COLS*HM_W-1:0]   hm_data_i,         // column c at [c*HM_W +: HM_W]
    input  wire                   hm_eof_i,          // end of frame
    // blob stream out
    output reg                    blob_valid_o,      // one blob
    output reg  [FRAME_W-1:0]     blob_frame_o,      // frame number (with valid and eof)
    output reg  [AREA_W-1:0]      blob_area_o,       // cells
    output reg  [15:0]            blob_cx_o,         // centroid column, Q8.8
    output reg  [15:0]            blob_cy_o,         // centroid row, Q8.8
    output reg  [ROW_IDX_W-1:0]   blob_rmin_o,       // bounding box, inclusive
    output reg  [COL_IDX_W-1:0]   blob_cmin_o,
    output reg  [ROW_IDX_W-1:0]   blob_rmax_o,
    output reg  [COL_IDX_W-1:0]   blob_cmax_o,
    output reg  [HM_W-1:0]        blob_peak_o,       // largest z of the blob
    output reg  [ROW_IDX_W-1:0]   blob_peak_row_o,   // first cell (raster order) holding it
    output reg  [COL_IDX_W-1:0]   blob_peak_col_o,
    output reg                    blob_eof_o,        // after the frame's last blob
    output reg  [CNT_W-1:0]       blob_count_o,      // blobs emitted (with blob_eof_o)
    output reg  [AREA_W-1:0]      blob_found_o,      // blobs in the frame (with blob_eof_o)
    output reg                    blob_overflow_o,   // found > MAX_BLOBS (with blob_eof_o)
    output reg                    blob_incomplete_o, // frame had missing rows: no blobs
    // blob membership of the cells (all blobs, also those beyond MAX_BLOBS)
    output reg                    mask_ready_o,      // the frame's mask is written (one cycle)
    output reg  [FRAME_W-1:0]     mask_frame_o,      // its frame number (with mask_ready_o)
    input  wire [ROW_IDX_W-1:0]   mask_q_row_i,      // cell to query: row
    input  wire [COL_IDX_W-1:0]   mask_q_col_i,      // cell to query: column
    output reg                    mask_q_data_o,     // 2 cycles later: the cell lies in a blob
    // monitor
    output reg                    overflow_flag_o,   // sticky: some frame had > MAX_BLOBS blobs
    output reg                    overrun_o          // sticky: frames arrived faster than processed
);

    // ---- sizes -------------------------------------------------------------------------
    // label slots 1..NL: every label live in two rows (P and C) plus the labels closed
    // at a row end that the close engine has not released yet (<= 6 cycles)
    localparam NL     = 2 * ((COLS + 1) / 2) + 12;
    localparam LBL_W  = $clog2(NL + 1);
    localparam SZ_W   = HM_W + AREA_W;               // sum z
    localparam SX_W   = SZ_W + COL_IDX_W;            // sum z*c
    localparam SY_W   = SZ_W + ROW_IDX_W;            // sum z*r
    localparam IDXMX  = (ROW_IDX_W > COL_IDX_W) ? ROW_IDX_W : COL_IDX_W;
    localparam QW     = IDXMX + 8;                   // centroid quotient bits (Q8.8)
    localparam DL     = QW + 3;                      // emission: slot, numerator, fmt_div (QW + 1)
    localparam NUM_W  = ((SX_W > SY_W) ? SX_W : SY_W) + 9;
    localparam GS     = 8;                           // columns per partial-sum group
    localparam NG     = (COLS + GS - 1) / GS;
    localparam GSZ_W  = HM_W + 4;                    // group sum of <= 8 cells
    localparam GSX_W  = GSZ_W + 3;                   // group sum of z * (c mod 8)
    localparam ADDR_W = $clog2(2 * ROWS);
    localparam RW     = COLS * HM_W;
    localparam IDX_W  = ROW_IDX_W + COL_IDX_W;
    localparam NPR    = (COLS + 1) / 2;              // column pairs
    localparam LR_W   = COLS + NPR * LBL_W;          // lr_mem word: on-cells, pair labels
    localparam MB     = MAX_BLOBS;
    localparam MBI_W  = (MB > 1) ? $clog2(MB) : 1;   // list index width
    // accumulator / list entry fields
    localparam O_AREA = 0;
    localparam O_SZ   = O_AREA + AREA_W;
    localparam O_SX   = O_SZ + SZ_W;
    localparam O_SY   = O_SX + SX_W;
    localparam O_RMIN = O_SY + SY_W;
    localparam O_FC   = O_RMIN + ROW_IDX_W;          // column of the first cell (row = rmin)
    localparam O_RMAX = O_FC + COL_IDX_W;
    localparam O_CMIN = O_RMAX + ROW_IDX_W;
    localparam O_CMAX = O_CMIN + COL_IDX_W;
    localparam O_PEAK = O_CMAX + COL_IDX_W;
    localparam O_PR   = O_PEAK + HM_W;
    localparam O_PC   = O_PR + ROW_IDX_W;
    localparam E_W    = O_PC + COL_IDX_W;
    // the accumulator memory in field slices (each with its own address registers; a
    // field's update uses its own slice only): {area, sum z}, sum z*c, sum z*r,
    // {rmin, first column, rmax, cmin, cmax}, {peak, its row and column}
    localparam NAS    = 5;
    // event FIFO between the extraction (E, X1..X5) and the labelling (L1, L2)
    localparam FP_W   = 5;                           // FIFO pointer width
    localparam FD     = 1 << FP_W;                   // entries (>= events of a row + 6)
    localparam FE_W   = 5 + 3 * COL_IDX_W + ROW_IDX_W + AREA_W + SZ_W + SX_W + SY_W + HM_W
                      + COL_IDX_W;                   // entry: see F_* below

    localparam integer ROWS_I = ROWS;
    localparam integer MB_I   = MAX_BLOBS;
    localparam [ADDR_W-1:0]    ROWS_A   = ROWS_I[ADDR_W-1:0];
    localparam [ROW_IDX_W:0]   ROWS_R   = ROWS_I[ROW_IDX_W:0];
    localparam [AREA_W-1:0]    MB_A     = MB_I[AREA_W-1:0];
    localparam [CNT_W-1:0]     MB_C     = MB_I[CNT_W-1:0];
    localparam integer LAST_ROW_I = ROWS - 1;
    localparam [ROW_IDX_W-1:0] LAST_ROW = LAST_ROW_I[ROW_IDX_W-1:0];

    // (loop variables are declared in their always block: one driver each, no latch)

    // ---- combine two partial regions: X precedes Y's peak in ties unless Y's peak cell
    // comes first in raster order; first cell = the smaller raster key
    function [E_W-1:0] combine;
        input [E_W-1:0] x;
        input [E_W-1:0] y;
        reg y_peak, x_first;
        begin
            combine = x;
            combine[O_AREA +: AREA_W] = x[O_AREA +: AREA_W] + y[O_AREA +: AREA_W];
            combine[O_SZ +: SZ_W]     = x[O_SZ +: SZ_W] + y[O_SZ +: SZ_W];
            combine[O_SX +: SX_W]     = x[O_SX +: SX_W] + y[O_SX +: SX_W];
            combine[O_SY +: SY_W]     = x[O_SY +: SY_W] + y[O_SY +: SY_W];
            if (y[O_RMAX +: ROW_IDX_W] > x[O_RMAX +: ROW_IDX_W])
                combine[O_RMAX +: ROW_IDX_W] = y[O_RMAX +: ROW_IDX_W];
            if (y[O_CMIN +: COL_IDX_W] < x[O_CMIN +: COL_IDX_W])
                combine[O_CMIN +: COL_IDX_W] = y[O_CMIN +: COL_IDX_W];
            if (y[O_CMAX +: COL_IDX_W] > x[O_CMAX +: COL_IDX_W])
                combine[O_CMAX +: COL_IDX_W] = y[O_CMAX +: COL_IDX_W];
            // larger peak, ties by raster index: one compare of {peak, ~index}
            y_peak = ({y[O_PEAK +: HM_W], ~y[O_PR +: ROW_IDX_W], ~y[O_PC +: COL_IDX_W]} >
                      {x[O_PEAK +: HM_W], ~x[O_PR +: ROW_IDX_W], ~x[O_PC +: COL_IDX_W]});
            if (y_peak) begin
                combine[O_PEAK +: HM_W]    = y[O_PEAK +: HM_W];
                combine[O_PR +: ROW_IDX_W] = y[O_PR +: ROW_IDX_W];
                combine[O_PC +: COL_IDX_W] = y[O_PC +: COL_IDX_W];
            end
            x_first = ({x[O_RMIN +: ROW_IDX_W], x[O_FC +: COL_IDX_W]} <
                       {y[O_RMIN +: ROW_IDX_W], y[O_FC +: COL_IDX_W]});
            if (!x_first) begin
                combine[O_RMIN +: ROW_IDX_W] = y[O_RMIN +: ROW_IDX_W];
                combine[O_FC +: COL_IDX_W]   = y[O_FC +: COL_IDX_W];
            end
        end
    endfunction

    // ---- frame buffers and arrival bookkeeping (as fmt_localmax) ----------------------
    // (the heat-map block RAM is one memory per GS columns, each read with its own
    // copy of the fetch enable: see g_mem)
    reg [ROWS-1:0]       arr_q [0:1];
    reg [1:0]            eofs_q;
    reg [FRAME_W-1:0]    frm_q [0:1];
    reg                  wb_q, pb_q;

    wire [ADDR_W-1:0] wr_addr = (wb_q ? ROWS_A : {ADDR_W{1'b0}})
                              + {{(ADDR_W-ROW_IDX_W){1'b0}}, hm_row_i};
    // the on-cells of every row (z >= blob_threshold_i as the row arrives)
    (* ram_style = "distributed" *)
    reg [COLS-1:0]       on_mem [0:(2<<ROW_IDX_W)-1];    // address {bank, row}
    reg [COLS-1:0]       hm_on;
    always @(*) begin : c_hm_on
        integer i;
        for (i = 0; i < COLS; i = i + 1)
            hm_on[i] = (hm_data_i[i*HM_W +: HM_W] >= blob_threshold_i);
    end
    always @(posedge clk) begin
        if (hm_valid_i)
            on_mem[{wb_q, hm_row_i}] <= hm_on;
    end
    wire [ROWS-1:0] arr_p = arr_q[pb_q];

    // min-cells per frame buffer: taken with every row that arrives into a buffer (the
    // caller holds it constant over a frame's rows: fmt_touch does); the close engine
    // uses the value of the buffer being labelled (mc_p_q, a register: a region closes
    // many cycles after its rows arrived, and after the release of the other buffer).
    reg  [MINC_W-1:0]    mc0_q, mc1_q, mc_p_q;
    always @(posedge clk) begin
        if (rst) begin
            mc0_q  <= {MINC_W{1'b0}};
            mc1_q  <= {MINC_W{1'b0}};
            mc_p_q <= {MINC_W{1'b0}};
        end else begin
            if (hm_valid_i && !wb_q) mc0_q <= blob_min_cells_i;
            if (hm_valid_i &&  wb_q) mc1_q <= blob_min_cells_i;
            mc_p_q <= pb_q ? mc1_q : mc0_q;
        end
    end

    localparam [1:0] S_RUN = 2'd0, S_EMIT = 2'd1, S_WAIT = 2'd2;
    reg [1:0] state_q;

    // ---- F: fetch: the row (block RAM: read register, then its output register) and
    // its on-cells (thresholded as the row arrived, on_mem); the second stage also
    // prepares the row's event starts against the previous row's on-cells ---------------
    wire                 f2_take;             // E takes the row in F2
    reg  [ROW_IDX_W:0]   fr_q;                // next row to fetch (ROWS = all fetched)
    reg  [ROWS-1:0]      fr_oh_q;             // fr_q one-hot (0: all fetched), for av_q
    reg  [ROW_IDX_W:0]   fr1_q;               // fr_q + 1, for av_q
    reg                  f1_v_q, f2_v_q;
    reg  [ROW_IDX_W-1:0] f1_row_q, f2_row_q;
    reg  [RW-1:0]        f1_z_q, f2_z_q;
    reg  [COLS-1:0]      f1_c_q, f2_c_q, f2_es_q, f2_fa_q, f2_b_q, f2_ge_q;
    reg                  f2_one_q;            // the row has at most one event
    reg  [COLS-1:0]      lastc_q;             // on-cells of the row fetched before (0: none)
    reg  [COLS-1:0]      f1_es_q, f1_fa_q;
    wire                 f1_mv = f1_v_q && (!f2_v_q || f2_take);
    wire                 fr_in = (fr_q < ROWS_R);
    wire [ROW_IDX_W-1:0] fr_row = fr_q[ROW_IDX_W-1:0];
    // The fetch decision from registers only: av_q = the next row is present (state
    // S_RUN, fr_q < ROWS, arr_p[fr_row]), registered from its next value (below, beside
    // the state machine); E takes F2's row this cycle (etk) from E's registers.  The wide
    // enables are per GS columns: fetch_g (the group's block-RAM read), mv_g (F2's
    // registers), take_g (E's registers), each from a kept copy of av_q, f1_v_q, f2_v_q
    // (no register drives hundreds of loads across the die).
    reg                  av_q;
    reg  [NG-1:0]        avc_q, f1vc_q, f2vc_q;
    wire                 etk;                 // E takes a row (f2_take = f2_v_q && etk)
    wire                 av_nx;
    wire                 fetch = av_q && (!f1_v_q || !f2_v_q || etk);
    wire [NG-1:0]        fetch_g = avc_q & {NG{!f1_v_q || !f2_v_q || etk}};
    wire [NG-1:0]        mv_g    = f1vc_q & {NG{!f2_v_q || etk}};
    wire [NG-1:0]        take_g  = f2vc_q & {NG{etk}};
    wire                 f1_v_nx = !rst && (fetch || (f1_v_q && !f1_mv));
    wire                 f2_v_nx = !rst && (f1_mv || (f2_v_q && !f2_take));
    wire [ADDR_W-1:0]    rd_addr = (pb_q ? ROWS_A : {ADDR_W{1'b0}})
                                 + {{(ADDR_W-ROW_IDX_W){1'b0}}, fr_row};
    // Events of a row (C: its on-cells, P: the previous row's): A = C & P; each C run
    // gives a run event at its start, labelled from its first A column (fa, none: a
    // new label), and every further A run inside it a merge event at the A run's start.
    // fa by one addition: the carry of a C run start runs through the run's C-only
    // cells and lands on its first A cell (or beyond the run: no A cell).
    wire [COLS-1:0]      on_f = on_mem[{pb_q, fr_row}];
    wire [COLS-1:0]      ca   = on_f & lastc_q;
    wire [COLS-1:0]      cy   = on_f & ~lastc_q;
    wire [COLS-1:0]      ccs  = on_f & ~{on_f[COLS-2:0], 1'b0};
    /* verilator lint_off UNUSEDSIGNAL */     // land[COLS]: a carry beyond the last column
    wire [COLS:0]        land = {1'b0, cy} + {1'b0, ccs};
    /* verilator lint_on UNUSEDSIGNAL */
    wire [COLS-1:0]      fa_f = land[COLS-1:0] & ~cy & on_f;
    wire [COLS-1:0]      es_f = ccs | (ca & ~{ca[COLS-2:0], 1'b0} & ~fa_f);
    wire [COLS-1:0]      es_neg = ~f1_es_q + 1'b1;    // the first event: lowest bit and up
    always @(posedge clk) begin
        if (fetch) begin
            f1_c_q   <= on_f;
            f1_es_q  <= es_f;
            f1_fa_q  <= fa_f;
            f1_row_q <= fr_row;
        end
        if (f1_mv) begin
            f2_one_q <= le1(f1_es_q);         // (not by the carry of es_neg: 9 levels)
            f2_row_q <= f1_row_q;
        end
    end

    // ---- E: event extraction, one event per cycle (lowest remaining event start) -------
    // at most two bits of x set: saturating unary counts {>= 3, >= 2, >= 1} of 4-bit
    // groups (each a function of its 4 bits), then a balanced pairwise tree of ucomb, by
    // AND / OR only (an adder or the form "r & (r - 1) == 0" becomes a carry chain
    // between LUTs, and a linear fold a LUT chain: 9-11 xc5v levels)
    localparam LE_G = (COLS + 3) / 4;                    // 4-bit groups
    localparam LE_P = (LE_G > 1) ? (1 << $clog2(LE_G)) : 1;   // leaves of the tree
    function [2:0] ucomb;                     // saturating sum of two unary counts
        input [2:0] a, b;
        ucomb = {a[2] | b[2] | (a[1] & b[0]) | (a[0] & b[1]), a[1] | b[1] | (a[0] & b[0]), a[0] | b[0]};
    endfunction
    function le2;                             // x has at most two bits set
        input [COLS-1:0] x;
        le2 = !ucnt(x, 1'b1);
    endfunction
    function le1;                             // x has at most one bit set
        input [COLS-1:0] x;
        le1 = !ucnt(x, 1'b0);
    endfunction
    function ucnt;                            // sel 1: >= 3 bits set, sel 0: >= 2
        input [COLS-1:0] x;
        input            sel;
        integer g, k, w;
        reg [3:0]        q;
        reg [3*LE_P-1:0] v;
        begin
            v = {3*LE_P{1'b0}};
            for (g = 0; g < LE_G; g = g + 1) begin
                q = 4'd0;
                for (k = 0; k < 4; k = k + 1)
                    if (4 * g + k < COLS) q[k] = x[4 * g + k];
                v[3 * g +: 3] = {(q[0] & q[1] & q[2]) | (q[0] & q[1] & q[3]) | (q[0] & q[2] & q[3]) | (q[1] & q[2] & q[3]),
                                 (q[0] & q[1]) | (q[0] & q[2]) | (q[0] & q[3]) | (q[1] & q[2]) | (q[1] & q[3]) | (q[2] & q[3]),
                                 |q};
            end
            for (w = LE_P / 2; w >= 1; w = w / 2)
                for (k = 0; k < w; k = k + 1)
                    v[3 * k +: 3] = ucomb(v[3 * (2 * k) +: 3], v[3 * (2 * k + 1) +: 3]);
            ucnt = sel ? v[2] : v[1];
        end
    endfunction

    reg                  e1_v_q, e1_first_q;
    reg  [ROW_IDX_W-1:0] e1_row_q;
    reg  [RW-1:0]        e1_z_q;
    reg  [COLS-1:0]      e1_c_q, e1_fa_q;
    reg  [COLS-1:0]      e1_rem_q;            // event starts not yet emitted (with b)
    reg  [COLS-1:0]      e1_b_q;              // this event's start (one-hot; 0: empty row)
    reg  [COLS-1:0]      e1_ge_q;             // columns >= e1_b_q
    reg  [FP_W:0]        res_q;               // events emitted by E and not taken by L1
    reg                  e1_last_q;           // this event is the row's last
    wire                 ev_last = e1_last_q;
    wire                 ev_go   = e1_v_q && !res_q[FP_W];   // res_q < FD
    assign               f2_take = f2_v_q && (!e1_v_q || (ev_go && ev_last));
    assign               etk     = !e1_v_q || (!res_q[FP_W] && e1_last_q);
    wire [COLS-1:0]      e1_remr = e1_rem_q & ~e1_b_q;
    wire [COLS-1:0]      e1_neg  = ~e1_remr + 1'b1;      // lowest bit and up: one carry
    wire [COLS-1:0]      e1_cs   = e1_c_q & ~{e1_c_q[COLS-2:0], 1'b0};
    wire                 ev_run  = |(e1_b_q & e1_cs);
    wire [COLS-1:0]      cge     = e1_c_q & e1_ge_q;
    // the C run starting at b for a run event (the carry of b & cs runs through it), 0
    // for a merge event; the label column: the run's first A cell, or a merge event's b
    // (no OR over the columns on these paths: ev_run is for the flags only)
    wire [COLS-1:0]      ev_m    = cge & ~(cge + (e1_b_q & e1_cs));
    wire [COLS-1:0]      ev_lc   = (e1_fa_q & ev_m) | (e1_b_q & ~e1_cs);

    // F2's and E's column registers and the heat-map block RAM, per GS columns
    genvar gm;
    generate
        for (gm = 0; gm < NG; gm = gm + 1) begin : g_mem
            localparam MW = ((gm + 1) * GS <= COLS) ? GS * HM_W : (COLS - gm * GS) * HM_W;
            (* ram_style = "block" *)         // one write, one read port: block RAM
            reg [MW-1:0] mem [0:2*ROWS-1];
            always @(posedge clk) begin
                if (hm_valid_i)
                    mem[wr_addr] <= hm_data_i[gm*GS*HM_W +: MW];
                if (fetch_g[gm])
                    f1_z_q[gm*GS*HM_W +: MW] <= mem[rd_addr];
            end
            (* keep *) always @(posedge clk) avc_q[gm]  <= av_nx;
            (* keep *) always @(posedge clk) f1vc_q[gm] <= f1_v_nx;
            (* keep *) always @(posedge clk) f2vc_q[gm] <= f2_v_nx;
            always @(posedge clk) begin
                if (mv_g[gm]) begin
                    f2_z_q[gm*GS*HM_W +: MW] <= f1_z_q[gm*GS*HM_W +: MW];
                    f2_c_q[gm*GS +: MW/HM_W]  <= f1_c_q[gm*GS +: MW/HM_W];
                    f2_es_q[gm*GS +: MW/HM_W] <= f1_es_q[gm*GS +: MW/HM_W];
                    f2_fa_q[gm*GS +: MW/HM_W] <= f1_fa_q[gm*GS +: MW/HM_W];
                    f2_b_q[gm*GS +: MW/HM_W]  <= f1_es_q[gm*GS +: MW/HM_W] & es_neg[gm*GS +: MW/HM_W];
                    f2_ge_q[gm*GS +: MW/HM_W] <= f1_es_q[gm*GS +: MW/HM_W] | es_neg[gm*GS +: MW/HM_W];
                end
                if (take_g[gm]) begin
                    e1_z_q[gm*GS*HM_W +: MW] <= f2_z_q[gm*GS*HM_W +: MW];
                    e1_c_q[gm*GS +: MW/HM_W]  <= f2_c_q[gm*GS +: MW/HM_W];
                    e1_fa_q[gm*GS +: MW/HM_W] <= f2_fa_q[gm*GS +: MW/HM_W];
                    e1_rem_q[gm*GS +: MW/HM_W] <= f2_es_q[gm*GS +: MW/HM_W];
                    e1_b_q[gm*GS +: MW/HM_W]   <= f2_b_q[gm*GS +: MW/HM_W];
                    e1_ge_q[gm*GS +: MW/HM_W]  <= f2_ge_q[gm*GS +: MW/HM_W];
                end else if (ev_go) begin
                    e1_rem_q[gm*GS +: MW/HM_W] <= e1_remr[gm*GS +: MW/HM_W];
                    e1_b_q[gm*GS +: MW/HM_W]   <= e1_remr[gm*GS +: MW/HM_W] & e1_neg[gm*GS +: MW/HM_W];
                    e1_ge_q[gm*GS +: MW/HM_W]  <= e1_remr[gm*GS +: MW/HM_W] | e1_neg[gm*GS +: MW/HM_W];
                end
            end
        end
    endgenerate

    // ---- X1..X5: the run's sums (X1: masked cells; X2: 8-column groups; X3: totals;
    // X4, X5: sum z*r = r * sum z by shift and add) -------------------------------------
    localparam EF_W = 5;                      // event flags: run, hy, last, first, last row
    reg                 x1_v_q;
    reg [EF_W-1:0]      x1_f_q;
    reg [COLS-1:0]      x1_m_q, x1_lc_q;
    reg [RW-1:0]        x1_z_q;               // the run's cells (the others 0: masked as
                                              // they are registered, a synchronous reset)
    reg [ROW_IDX_W-1:0] x1_row_q;
    // ---- X2: group sums, run extent ---------------------------------------------------
    reg [ROW_IDX_W-1:0] x2_row_q;
    reg [NG*GSZ_W-1:0]  x2_gs_q;
    reg [NG*GSX_W-1:0]  x2_gx_q;
    reg [COL_IDX_W-1:0] x2_cmin_q, x2_cmax_q;
    reg [NG*GSZ_W-1:0]  gs;
    reg [NG*GSX_W-1:0]  gx;
    reg [COL_IDX_W-1:0] cmin, cmax;
    reg [COLS-1:0]      m_first, m_last, m_t0, m_t1;
    reg [GS*HM_W-1:0]   gz;
    reg [HM_W+1:0]      gu [0:3];             // HM_W + 2 bits: gu[1] + gu[3] below fits
    reg [HM_W+1:0]      gv0, gv1, go;
    reg                 x2_v_q;
    reg [EF_W-1:0]      x2_f_q;
    reg [COL_IDX_W-1:0] x2_lc_q;
    // one-hot -> index: bit b = OR of the one-hot bits whose index has bit b (a balanced
    // OR, not a chain)
    reg [COL_IDX_W-1:0] lc_enc;
    reg [COLS-1:0]      lc_t;
    always @(*) begin : c_lc_enc
        integer i, b;
        for (b = 0; b < COL_IDX_W; b = b + 1) begin
            for (i = 0; i < COLS; i = i + 1)
                lc_t[i] = x1_lc_q[i] && (((i >> b) & 1) == 1);
            lc_enc[b] = |lc_t;
        end
    end
    always @(*) begin : c_x2
        integer i, g;
        gs = {(NG*GSZ_W){1'b0}};
        gx = {(NG*GSX_W){1'b0}};
        for (g = 0; g < NG; g = g + 1) begin
            // the group's 8 masked cells (0 beyond the last column)
            for (i = 0; i < GS; i = i + 1)
                gz[i*HM_W +: HM_W] = (g * GS + i < COLS)
                                   ? x1_z_q[((g * GS + i < COLS) ? g * GS + i : 0)*HM_W +: HM_W]
                                   : {HM_W{1'b0}};
            // sum z and sum z * (c mod 8) by a balanced tree of 13 adders:
            // u_i = z_2i + z_2i+1, v_0 = u_0 + u_1, v_1 = u_2 + u_3, sum = v_0 + v_1,
            // sum j z_j = 4 v_1 + 2 (u_1 + u_3) + (z_1 + z_3 + z_5 + z_7)
            for (i = 0; i < 4; i = i + 1)
                gu[i] = {2'b00, gz[(2*i)*HM_W +: HM_W]} + {2'b00, gz[(2*i+1)*HM_W +: HM_W]};
            gv0 = gu[0] + gu[1];
            gv1 = gu[2] + gu[3];
            go  = ({2'b00, gz[1*HM_W +: HM_W]} + {2'b00, gz[3*HM_W +: HM_W]})
                + ({2'b00, gz[5*HM_W +: HM_W]} + {2'b00, gz[7*HM_W +: HM_W]});
            gs[g*GSZ_W +: GSZ_W] = {{(GSZ_W-HM_W-2){1'b0}}, gv0} + {{(GSZ_W-HM_W-2){1'b0}}, gv1};
            gx[g*GSX_W +: GSX_W] = {{(GSX_W-HM_W-5){1'b0}}, gv1, 2'b00}
                                 + {{(GSX_W-HM_W-3){1'b0}}, gu[1] + gu[3], 1'b0}
                                 + {{(GSX_W-HM_W-2){1'b0}}, go};
        end
        // the run's first and last column: one-hot, then encoded (balanced ORs)
        for (i = 0; i < COLS; i = i + 1) begin
            m_first[i] = x1_m_q[i] && (i == 0 || !x1_m_q[(i > 0) ? i - 1 : 0]);
            m_last[i]  = x1_m_q[i] && (i == COLS - 1 || !x1_m_q[(i < COLS - 1) ? i + 1 : 0]);
        end
        for (g = 0; g < COL_IDX_W; g = g + 1) begin
            for (i = 0; i < COLS; i = i + 1) begin
                m_t0[i] = m_first[i] && (((i >> g) & 1) == 1);
                m_t1[i] = m_last[i] && (((i >> g) & 1) == 1);
            end
            cmin[g] = |m_t0;
            cmax[g] = |m_t1;
        end
    end

    // Peak of the run (largest z, the leftmost among equals): a tournament over the
    // masked cells, two levels per stage (X2, X3, X4); an entry is {z, column}, the
    // right one of a pair wins only when strictly larger.
    localparam PK_W = HM_W + COL_IDX_W;
    localparam PN0 = COLS, PN1 = (PN0 + 1) / 2, PN2 = (PN1 + 1) / 2, PN3 = (PN2 + 1) / 2;
    localparam PN4 = (PN3 + 1) / 2, PN5 = (PN4 + 1) / 2, PN6 = (PN5 + 1) / 2;   // 1: COLS <= 64
    function [PN0*PK_W-1:0] pk_half;          // entry k = winner of entries 2k, 2k+1 of v
        input [PN0*PK_W-1:0] v;
        input integer        n;               // entries in v
        integer k, j;
        begin
            pk_half = {(PN0*PK_W){1'b0}};
            for (k = 0; k < PN0; k = k + 1) begin
                j = (2 * k + 1 < PN0) ? 2 * k + 1 : PN0 - 1;
                if (2 * k + 1 < n && v[j*PK_W + COL_IDX_W +: HM_W]
                                     > v[(j-1)*PK_W + COL_IDX_W +: HM_W])
                    pk_half[k*PK_W +: PK_W] = v[j*PK_W +: PK_W];
                else if (2 * k < n)
                    pk_half[k*PK_W +: PK_W] = v[(2*k < PN0 ? 2*k : 0)*PK_W +: PK_W];
            end
        end
    endfunction
    reg  [PN0*PK_W-1:0] pk0;
    always @(*) begin : c_pk0
        integer i;
        for (i = 0; i < COLS; i = i + 1)
            pk0[i*PK_W +: PK_W] = {x1_z_q[i*HM_W +: HM_W],
                                   i[COL_IDX_W-1:0]};
    end
    // levels per stage: X2 one, X3 two, X4 two, X5 one
    reg  [PN1*PK_W-1:0] x2_pk_q;
    reg  [PN3*PK_W-1:0] x3_pk_q;
    reg  [PN5*PK_W-1:0] y4_pk_q;
    /* verilator lint_off UNUSEDSIGNAL */     // entries beyond a level's count are 0
    wire [PN0*PK_W-1:0] pk1 = pk_half(pk0, PN0);
    wire [PN0*PK_W-1:0] pk2 = pk_half({{((PN0-PN1)*PK_W){1'b0}}, x2_pk_q}, PN1);
    wire [PN0*PK_W-1:0] pk3 = pk_half(pk2, PN2);
    wire [PN0*PK_W-1:0] pk4 = pk_half({{((PN0-PN3)*PK_W){1'b0}}, x3_pk_q}, PN3);
    wire [PN0*PK_W-1:0] pk5 = pk_half(pk4, PN4);
    wire [PN0*PK_W-1:0] pk6 = pk_half({{((PN0-PN5)*PK_W){1'b0}}, y4_pk_q}, PN5);
    /* verilator lint_on UNUSEDSIGNAL */
    // synthesis translate_off
    initial begin
        if (PN6 != 1) begin
            $display("fmt_blob: COLS %0d > 64: the peak tournament needs more levels", COLS);
            $finish;
        end
    end
    // synthesis translate_on

    // ---- X3: totals -----------------------------------------------------------------------
    reg                 x3_v_q;
    reg [EF_W-1:0]      x3_f_q;
    reg [COL_IDX_W-1:0] x3_lc_q;
    reg [ROW_IDX_W-1:0] x3_row_q;
    reg [AREA_W-1:0]    x3_cnt_q;
    reg [COL_IDX_W-1:0] x3_cmin_q, x3_cmax_q;
    reg [SZ_W-1:0]      x3_s_q;
    // sum z*c = sum over the groups of (sum z*(c mod 8) + 8g * sum z): X3 adds the
    // groups' sums z*(c mod 8) (a balanced tree) and T = sum g * (sum z of group g)
    // (by the bits of g), X4 adds the two: sum z*c = that sum + 8 T
    localparam NGB   = (NG > 1) ? $clog2(NG) : 1;           // bits of a group index
    localparam GXT_W = GSX_W + NGB;                          // sum of the groups' gx
    localparam GT_W  = GSZ_W + $clog2(NG * (NG - 1) / 2 + 1); // T
    reg [GXT_W-1:0]     x3_gx_q;
    reg [GT_W-1:0]      x3_gt_q;
    reg [NG*SZ_W-1:0]   tr_s;                 // sum z: a balanced tree over the groups
    reg [NG*GXT_W-1:0]  tr_g;                 // sum z*(c mod 8): the same tree
    reg [NGB*GT_W-1:0]  gtb;                  // per bit b of g: sum of the groups' sum z
    reg [GT_W-1:0]      gt;
    always @(*) begin : c_x3
        integer g, b, n;
        gtb = {(NGB*GT_W){1'b0}};
        for (g = 0; g < NG; g = g + 1) begin
            tr_s[g*SZ_W +: SZ_W]   = {{(SZ_W-GSZ_W){1'b0}}, x2_gs_q[g*GSZ_W +: GSZ_W]};
            tr_g[g*GXT_W +: GXT_W] = {{(GXT_W-GSX_W){1'b0}}, x2_gx_q[g*GSX_W +: GSX_W]};
            for (b = 0; b < NGB; b = b + 1)
                if (((g >> b) & 1) == 1)
                    gtb[b*GT_W +: GT_W] = gtb[b*GT_W +: GT_W]
                                        + {{(GT_W-GSZ_W){1'b0}}, x2_gs_q[g*GSZ_W +: GSZ_W]};
        end
        gt = {GT_W{1'b0}};
        for (b = 0; b < NGB; b = b + 1)
            gt = gt + (gtb[b*GT_W +: GT_W] << b);
        // pairwise: entry k = entries 2k + 2k+1 (written after both are read)
        for (n = NG; n > 1; n = (n + 1) / 2)
            for (g = 0; g < (n + 1) / 2; g = g + 1)
                if (2 * g + 1 < n) begin
                    tr_s[g*SZ_W +: SZ_W] = tr_s[(2*g)*SZ_W +: SZ_W]
                                         + tr_s[((2*g+1 < NG) ? 2*g+1 : 0)*SZ_W +: SZ_W];
                    tr_g[g*GXT_W +: GXT_W] = tr_g[(2*g)*GXT_W +: GXT_W]
                                           + tr_g[((2*g+1 < NG) ? 2*g+1 : 0)*GXT_W +: GXT_W];
                end else begin
                    tr_s[g*SZ_W +: SZ_W]   = tr_s[(2*g)*SZ_W +: SZ_W];
                    tr_g[g*GXT_W +: GXT_W] = tr_g[(2*g)*GXT_W +: GXT_W];
                end
    end
    // X4: sum z*c
    wire [SX_W-1:0] sx4 = {{(SX_W-GXT_W){1'b0}}, x3_gx_q} + ({{(SX_W-GT_W){1'b0}}, x3_gt_q} << $clog2(GS));


    // ---- X4, X5: sum z*r = r * sum z, shift and add (low and high row bits, then both)
    localparam RH = ROW_IDX_W / 2;            // row bits of the first partial product
    reg                 y4_v_q, y5_v_q;
    /* verilator lint_off UNUSEDSIGNAL */     // y4_e_q's sum z*r and peak fields are 0
    reg [FE_W-1:0]      y4_e_q;               // the event (its sum z*r field: 0 in X4)
    /* verilator lint_on UNUSEDSIGNAL */
    reg [FE_W-1:0]      y5_e_q;
    reg [SY_W-1:0]      y4_ylo_q, y4_yhi_q;
    reg [SX_W-1:0]      y4_sx_q;
    reg [SY_W-1:0]      ylo, yhi;
    always @(*) begin : c_sy
        integer b;
        ylo = {SY_W{1'b0}};
        yhi = {SY_W{1'b0}};
        for (b = 0; b < ROW_IDX_W; b = b + 1) begin
            if (x3_row_q[b] && b < RH)  ylo = ylo + ({{(SY_W-SZ_W){1'b0}}, x3_s_q} << b);
            if (x3_row_q[b] && b >= RH) yhi = yhi + ({{(SY_W-SZ_W){1'b0}}, x3_s_q} << b);
        end
    end
    // FIFO entry: flags, label column, row, area, sums, peak and its column, extent
    localparam F_FL  = 0;
    localparam F_LC  = F_FL + EF_W;
    localparam F_ROW = F_LC + COL_IDX_W;
    localparam F_CNT = F_ROW + ROW_IDX_W;
    localparam F_SZ  = F_CNT + AREA_W;
    localparam F_SX  = F_SZ + SZ_W;
    localparam F_SY  = F_SX + SX_W;
    localparam F_PK  = F_SY + SY_W;
    localparam F_PC  = F_PK + HM_W;
    localparam F_CMN = F_PC + COL_IDX_W;
    localparam F_CMX = F_CMN + COL_IDX_W;
    wire [FE_W-1:0] x3_ev = {x3_cmax_q, x3_cmin_q, {(COL_IDX_W+HM_W+SY_W+SX_W){1'b0}},
                             x3_s_q, x3_cnt_q, x3_row_q, x3_lc_q, x3_f_q};
    wire [FE_W-1:0] y4_ev;
    assign y4_ev[F_SX-1:0]         = y4_e_q[F_SX-1:0];
    assign y4_ev[F_SX +: SX_W]     = y4_sx_q;
    assign y4_ev[F_SY +: SY_W]     = y4_ylo_q + y4_yhi_q;
    assign y4_ev[F_PK +: HM_W]     = pk6[COL_IDX_W +: HM_W];
    assign y4_ev[F_PC +: COL_IDX_W] = pk6[0 +: COL_IDX_W];
    assign y4_ev[FE_W-1:F_CMN]     = y4_e_q[FE_W-1:F_CMN];

    // ---- the event FIFO (distributed RAM), read into L1 --------------------------------
    (* ram_style = "distributed" *)
    reg [FE_W-1:0]  fmem [0:FD-1];
    reg [FP_W-1:0]  fwp_q, frp_q;
    reg [FP_W:0]    fcnt_q;
    wire            adv;                      // L0..L2 advance (L2 does not wait)
    wire            fpop = (fcnt_q != {(FP_W+1){1'b0}}) && adv;
    always @(posedge clk) begin
        if (y5_v_q) fmem[fwp_q] <= y5_e_q;
    end
    wire [FE_W-1:0]  f_rd = fmem[frp_q];
    reg  [COLS-1:0]  lc_oh;                   // the label column, decoded
    always @(*) begin : c_lc_oh
        integer i;
        for (i = 0; i < COLS; i = i + 1)
            lc_oh[i] = (f_rd[F_LC +: COL_IDX_W] == i[COL_IDX_W-1:0]);
    end

    // ---- L: labelling, one event per cycle -----------------------------------------------
    // L1 looks up the P label under the event's label column (P and C eagerly renamed,
    // forwarded from this cycle's L2 step); L2 applies the event:
    //   run event, a P label y -> ADD(y): the C run's cells get y
    //   run event, no P label  -> NEW(n): n = a free label (prefetched, n0_q)
    //   merge event, y != x    -> MERGE(x <- y): x = the C run's label; y is renamed x
    //                             in P, C and alias, and is free again
    //   the row's last event ends the row: P's labels no longer in C are closed, P = C.
    reg [COLS*LBL_W-1:0] p_q, c_q;            // labels of the previous / current row
    reg [NL:1]           livep_q, livec_q;    // labels present in P / in C
    reg [NL:1]           free_q;              // free label slots (n0_q excluded)
    reg [NL:1]           pend_q;              // closed labels waiting for the close engine
    reg [LBL_W-1:0]      n0_q;                // the next NEW label
    reg                  n0v_q;
    reg [LBL_W-1:0]      x_q;                 // label of the current C run
    reg                  l0_v_q;
    reg [FE_W-1:0]       l0_e_q;
    reg [COLS-1:0]       l0_oh_q;             // the label column, one-hot
    reg                  lg_v_q;              // LG: the label gathered from the groups
    reg [FE_W-1:0]       lg_e_q;
    reg [COLS-1:0]       lg_oh_q;
    reg [NG*LBL_W-1:0]   lg_yg_q;             // per GS columns: the label (0 off its group)
    reg                  lg_hp_q;             // LG's label column under that step's run
    reg                  l1_v_q;
    reg [FE_W-1:0]       l1_e_q;
    reg [COLS-1:0]       l1_oh_q;
    reg [COLS-1:0]       l1_m_q;              // the C run's columns
    reg [LBL_W-1:0]      l1_y_q;              // the label, up to date but for this cycle's step
    reg                  l2_v_q;
    /* verilator lint_off UNUSEDSIGNAL */     // L2 does not use the label column
    reg [FE_W-1:0]       l2_e_q;
    wire [EF_W-1:0]      l0_f  = l0_e_q[F_FL +: EF_W];    // L0, L1 use the first flag only
    wire [EF_W-1:0]      lg_f  = lg_e_q[F_FL +: EF_W];
    wire [EF_W-1:0]      l1_f  = l1_e_q[F_FL +: EF_W];
    wire [EF_W-1:0]      l2_f  = l2_e_q[F_FL +: EF_W];    // L2: all but the first flag
    wire             new_wait /* verilator public_flat_rd */;   // a NEW waits for a free label
                                              // (read by tb/fmt_blob under both simulators)
    /* verilator lint_on UNUSEDSIGNAL */
    reg [LBL_W-1:0]      l2_y_q;              // the P label under the event (if hy)
    reg [COLS-1:0]       l2_m_q;              // the C run's columns (run events)
    wire                 l2_isrun = l2_f[0], l2_hy = l2_f[1], l2_last = l2_f[2],
                         l2_lastrow = l2_f[4];
    wire [ROW_IDX_W-1:0] l2_row = l2_e_q[F_ROW +: ROW_IDX_W];
    wire [COL_IDX_W-1:0] l2_cmin = l2_e_q[F_CMN +: COL_IDX_W];
    // L2 step
    wire             l2_stall = l2_v_q && l2_isrun && !l2_hy && !n0v_q;   // NEW waits
    // step, run and row end registered from their next values (st_q, run_q, rd_q, below),
    // with copies like those of the merge
    reg              st_q, run_q, rd_q;
    reg  [NG+NAG:0]  runc_q, rdc_q;           // copies (indices as yc_q's)
    wire             step     = st_q;
    wire             do_run   = run_q;
    wire             do_new   = do_run && !l2_hy;
    // a merge (its event has a label y != x): decided when L2 loads (dm_q; a merge never
    // waits in L2), with copies of dm_q, x_q and l2_y_q for the wide renames (keep)
    reg              dm_q;
    wire             do_merge = dm_q;
    localparam NAG = 4;                       // alias groups (of ALG labels) with own copies
    localparam ALG = (NL + NAG - 1) / NAG;
    localparam NYC = NG + NAG + 1;            // copies: per GS columns of P and C, per alias
                                              // group, one for the label masks (VC)
    localparam VC  = NG + NAG;
    reg  [NYC*LBL_W-1:0] yc_q, xc_q;          // copies of l2_y_q, x_q
    reg  [NYC-1:0]       dmc_q;               // copies of dm_q
    reg  [NYC-1:0]       clrc_q;              // clear P, C, alias, live masks (copies)
    localparam NAD = 12;                      // copies of adv: 2 for L0, 3 each LG, L1, L2,
                                              // one for the merge decision
    reg  [NAD-1:0]       advc_q;
    wire                 releasing;           // the frame is released (S_WAIT -> S_RUN)
    wire             row_done = rd_q;
    wire [LBL_W-1:0] lrun     = l2_hy ? l2_y_q : n0_q;
    assign           new_wait = l2_stall;
    reg  [NL:1]      vbit, rbit;              // one-hot of the merge victim, the run label
    always @(*) begin : c_bits
        integer i;
        for (i = 1; i <= NL; i = i + 1) begin
            vbit[i] = (yc_q[VC*LBL_W +: LBL_W] == i[LBL_W-1:0]);
            rbit[i] = (lrun == i[LBL_W-1:0]);
        end
    end
    // L0 looks up the event's label column in P, or in C when L2 may end the previous row
    // before the event's own row starts (C becomes P): C when its event is the first of
    // its row, or when LG or L1 holds that first event.  L0 selects per GS columns only
    // (the one-hot select beside each group of P and C, registered per group: lg_yg_q);
    // the step of that cycle is registered (s_*) and applied in LG, which gathers the
    // groups; the step of LG's cycle is applied in L1, the step of L1's cycle in L2's load.
    wire             bnd = l0_f[3] || (lg_v_q && lg_f[3]) || (l1_v_q && l1_f[3]);
    reg  [NG*LBL_W-1:0] y0g;                  // per group: the label under the column, or 0
    reg  [COLS-1:0]  ren_p, ren_c;            // column holds the victim label
    reg  [COLS-1:0]  l1_m;
    reg  [GS-1:0]    t_p, t_c;
    always @(*) begin : c_l0
        integer g, i, b;
        for (g = 0; g < NG; g = g + 1)
            for (b = 0; b < LBL_W; b = b + 1) begin
                for (i = 0; i < GS; i = i + 1) begin
                    t_p[i] = (g * GS + i < COLS) && l0_oh_q[(g * GS + i < COLS) ? g * GS + i : 0]
                             && p_q[((g * GS + i < COLS) ? g * GS + i : 0) * LBL_W + b];
                    t_c[i] = (g * GS + i < COLS) && l0_oh_q[(g * GS + i < COLS) ? g * GS + i : 0]
                             && c_q[((g * GS + i < COLS) ? g * GS + i : 0) * LBL_W + b];
                end
                y0g[g * LBL_W + b] = bnd ? |t_c : |t_p;
            end
        for (i = 0; i < COLS; i = i + 1) begin
            ren_p[i] = (p_q[i*LBL_W +: LBL_W] == yc_q[(i/GS)*LBL_W +: LBL_W]);
            ren_c[i] = (c_q[i*LBL_W +: LBL_W] == yc_q[(i/GS)*LBL_W +: LBL_W]);
            l1_m[i] = (i[COL_IDX_W-1:0] >= lg_e_q[F_CMN +: COL_IDX_W])
                   && (i[COL_IDX_W-1:0] <= lg_e_q[F_CMX +: COL_IDX_W]);
        end
    end
    wire             l0_hp  = bnd && |(l0_oh_q & l2_m_q);  // under this cycle's run, if any
    reg              s_mrg_q, s_run_q;        // the step of the cycle before: a merge, a run
    reg  [LBL_W-1:0] s_v_q, s_x_q, s_lrun_q;  // its victim, survivor, run label
    reg              l1_hp_q;                 // L1's label column under that step's run
    // LG: the groups gathered (one is nonzero at most), the step of the cycle before
    // applied (yga); LG's label column under this cycle's run (only when LG reads C: its
    // event is the first of its row or L1 holds that first event)
    reg  [LBL_W-1:0] lg_y;
    wire             sg_run = lg_hp_q && s_run_q;
    wire             sg_mrg = s_mrg_q && (lg_y == s_v_q);
    wire [LBL_W-1:0] yga = sg_run ? s_lrun_q : (sg_mrg ? s_x_q : lg_y);
    wire             eqg = sg_run ? (s_lrun_q == l2_y_q)     // (yga == l2_y_q), the three
                         : (sg_mrg ? (s_x_q == l2_y_q) : (lg_y == l2_y_q));   // compared beside
    reg  [NG*LBL_W-1:0] yga_g;                // yga in group 0 (LG held)
    always @(*) begin : c_lg
        integer g;
        lg_y = {LBL_W{1'b0}};
        for (g = 0; g < NG; g = g + 1) lg_y = lg_y | lg_yg_q[g*LBL_W +: LBL_W];
        yga_g = {(NG*LBL_W){1'b0}};
        yga_g[LBL_W-1:0] = yga;
    end
    wire             lg_hp = (lg_f[3] || (l1_v_q && l1_f[3])) && |(lg_oh_q & l2_m_q);
    // L1's label after the step of the cycle before (ya), and whether it is this
    // cycle's merge victim (eqa: the three candidates compared beside the select)
    wire             sa_run = l1_hp_q && s_run_q;
    // (l1_sv_q = (l1_y_q == s_v_q), registered beside them: s_v_q is l2_y_q of the cycle
    // before, compared in LG with L1's next label)
    reg              l1_sv_q;
    wire             sa_mrg = s_mrg_q && l1_sv_q;
    wire [LBL_W-1:0] ya  = sa_run ? s_lrun_q : (sa_mrg ? s_x_q : l1_y_q);
    wire             eqa = sa_run ? (s_lrun_q == l2_y_q)
                         : (sa_mrg ? (s_x_q == l2_y_q) : (l1_y_q == l2_y_q));
    // L1: this cycle's step (a run of the previous row only for the row's first event)
    // (l1_ov_q: L1's label column under L2's run mask, registered from its next value:
    // when the stages advance, LG's column and L1's run)
    reg              l1_ov_q, l1_mg_q;        // l1_mg_q: L1 holds a merge event with a label
    wire             l1_hit = l1_f[3] && do_run && l1_ov_q;
    wire [LBL_W-1:0] y1 = l1_hit ? lrun : ((do_merge && eqa) ? x_q : ya);
    // L0, LG, L1 and L2 advance together (a bubble moves too) unless L2 waits (a NEW
    // without a free label): adv; the wide loads of the stages' registers take kept
    // copies of it, registered from its next value (no gates in front of the enables)
    assign           adv   = !l2_v_q || step;
    wire             l2_ld = l1_v_q && adv;
    // the event L2 loads is a merge with y1 != x (x after this cycle's step): y1 is lrun
    // (l1_hit: x becomes lrun) or x_q (a merge now: x stays), or else ya
    wire [LBL_W-1:0] x_nx  = do_run ? lrun : x_q;
    wire             ne_nx = !l1_hit && !(do_merge && eqa)
                          && (sa_run ? (s_lrun_q != x_nx) : (sa_mrg ? (s_x_q != x_nx) : (l1_y_q != x_nx)));
    wire             dm_nx = !rst && advc_q[NAD-1] && l1_mg_q && ne_nx;
    always @(posedge clk) dm_q <= dm_nx;
    // next L2 state: valid, flags, and whether a NEW label is ready (n0v_q's next)
    wire             l2v_nx  = !rst && (l2_ld || (l2_v_q && !step));
    wire [2:0]       l2f_nx  = l2_ld ? l1_f[2:0] : l2_f[2:0];
    wire             n0v_nx  = !rst && !releasing && (n0_fill ? |free_q : n0v_q);
    wire             st_nx   = l2v_nx && !(l2f_nx[0] && !l2f_nx[1] && !n0v_nx);
    wire             adv_nx  = !l2v_nx || st_nx;
    wire             run_nx  = st_nx && l2f_nx[0];
    wire             rd_nx   = st_nx && l2f_nx[2];
    always @(posedge clk) begin
        st_q  <= st_nx;
        run_q <= run_nx;
        rd_q  <= rd_nx;
    end
    genvar gy;
    generate
        for (gy = 0; gy < NYC; gy = gy + 1) begin : g_yc
            (* keep *) always @(posedge clk) dmc_q[gy] <= dm_nx;
            (* keep *) always @(posedge clk) runc_q[gy] <= run_nx;
            (* keep *) always @(posedge clk) rdc_q[gy] <= rd_nx;
            // (no clock enables: synthesis keeps a kept flip-flop's feedback multiplexer;
            // the copies of l2_y_q are read only for a merge, which L2 loaded the cycle before)
            (* keep *) always @(posedge clk) yc_q[gy*LBL_W +: LBL_W] <= y1;
            (* keep *) always @(posedge clk) xc_q[gy*LBL_W +: LBL_W] <= x_nx;
            (* keep *) always @(posedge clk) clrc_q[gy] <= rst || releasing;
        end
        for (gy = 0; gy < NAD; gy = gy + 1) begin : g_adv
            (* keep *) always @(posedge clk) advc_q[gy] <= adv_nx;
        end
    endgenerate
    // synthesis translate_off
    reg rst_seen;                             // (the copies are loaded from the reset on)
    initial rst_seen = 1'b0;
    always @(posedge clk) if (rst) rst_seen <= 1'b1;
    always @(posedge clk) begin
        if (!rst && l2_v_q && (dm_q !== (step && !l2_isrun && l2_hy && (l2_y_q != x_q)))) begin
            $display("fmt_blob: dm_q %b differs from the merge condition", dm_q);
            $finish;
        end
        if (!rst && dm_q && (yc_q !== {NYC{l2_y_q}} || xc_q !== {NYC{x_q}})) begin
            $display("fmt_blob: a copy of l2_y_q or x_q differs in a merge");
            $finish;
        end
        if (!rst && rst_seen && (l1_mg_q !== (l1_v_q && !l1_f[0] && l1_f[1])
                                 || l1_sv_q !== (l1_y_q == s_v_q)
                                 || (l1_v_q && l1_ov_q !== |(l1_oh_q & l2_m_q)))) begin
            $display("fmt_blob: l1_mg_q, l1_sv_q or l1_ov_q differs");
            $finish;
        end
        if (!rst && rst_seen && advc_q !== {NAD{adv}}) begin
            $display("fmt_blob: a copy of adv differs");
            $finish;
        end
        if (!rst && (st_q !== (l2_v_q && !l2_stall) || run_q !== (l2_v_q && !l2_stall && l2_isrun)
                     || rd_q !== (l2_v_q && !l2_stall && l2_last))) begin
            $display("fmt_blob: st_q %b run_q %b rd_q %b differ from the step", st_q, run_q, rd_q);
            $finish;
        end
    end
    // synthesis translate_on

    // next label vectors and live masks of this cycle's step
    reg [COLS*LBL_W-1:0] p_nx, c_nx;
    reg [NL:1]           livep_nx, livec_nx;
    always @(*) begin : c_step
        integer i;
        p_nx = p_q;
        c_nx = c_q;
        for (i = 0; i < COLS; i = i + 1) begin
            if (dmc_q[i/GS] && ren_p[i]) p_nx[i*LBL_W +: LBL_W] = xc_q[(i/GS)*LBL_W +: LBL_W];
            if (dmc_q[i/GS] && ren_c[i]) c_nx[i*LBL_W +: LBL_W] = xc_q[(i/GS)*LBL_W +: LBL_W];
            if (runc_q[i/GS] && l2_m_q[i]) c_nx[i*LBL_W +: LBL_W] = lrun;
        end
        livep_nx = livep_q & ~(dmc_q[VC] ? vbit : {NL{1'b0}});
        livec_nx = (livec_q & ~(dmc_q[VC] ? vbit : {NL{1'b0}})) | (runc_q[VC] ? rbit : {NL{1'b0}});
    end
    // free labels: the lowest one is prefetched into n0_q
    wire        n0_fill = !n0v_q || do_new;
    wire [NL:1] f_low   = free_q & (~free_q + 1'b1);
    reg  [LBL_W-1:0] f_enc;
    reg  [NL:1]      f_t;
    always @(*) begin : c_fenc
        integer i, b;
        for (b = 0; b < LBL_W; b = b + 1) begin
            for (i = 1; i <= NL; i = i + 1)
                f_t[i] = f_low[i] && (((i >> b) & 1) == 1);
            f_enc[b] = |f_t;
        end
    end

    // Records for the membership pass: the labels of every row at its end (after its
    // merges), and, written at the end of row r+1 about the labels of row r, which of
    // them continued into row r+1 (cont) and as which label of row r+1 (alias: renamed
    // by the merges of row r+1).
    reg [NL*LBL_W-1:0]  alias_q, alias_nx, alias_id;
    always @(*) begin : c_alias
        integer i;
        for (i = 1; i <= NL; i = i + 1) begin
            alias_id[(i-1)*LBL_W +: LBL_W] = i[LBL_W-1:0];
            alias_nx[(i-1)*LBL_W +: LBL_W] =
                (dmc_q[NG + (i-1)/ALG]
                 && alias_q[(i-1)*LBL_W +: LBL_W] == yc_q[(NG + (i-1)/ALG)*LBL_W +: LBL_W])
                ? xc_q[(NG + (i-1)/ALG)*LBL_W +: LBL_W] : alias_q[(i-1)*LBL_W +: LBL_W];
        end
    end
    wire [NL:1] cont_rec = ~(livep_nx & ~livec_nx);
    (* ram_style = "block" *)                 // one write, one synchronous read
    reg [LR_W-1:0]           lr_mem [0:ROWS-1];     // {on-cells, pair labels} of a row
    (* ram_style = "block" *)
    reg [NL*(LBL_W+1)-1:0]   fr_mem [0:ROWS-1];
    // The run's cells share its label at the row end, and two run starts are never
    // adjacent: per column pair one label is kept, the label of the pair's run start (if
    // any).  Written one cycle after the row end, from C and the row's on-cells then.
    reg                  lr_we_q;
    reg [ROW_IDX_W-1:0]  lr_row_q;
    wire [COLS-1:0]      on_l2 = on_mem[{pb_q, l2_row}];     // the row's on-cells
    reg [COLS-1:0]       lr_on_q;
    reg [NPR*LBL_W-1:0]  lr_pl;
    always @(*) begin : c_lr_pl
        integer j;
        for (j = 0; j < NPR; j = j + 1)
            if (2 * j + 1 >= COLS
                || (lr_on_q[2*j] && (j == 0 || !lr_on_q[(j > 0) ? 2*j-1 : 0])))
                lr_pl[j*LBL_W +: LBL_W] = c_q[(2*j)*LBL_W +: LBL_W];
            else
                lr_pl[j*LBL_W +: LBL_W] = c_q[((2*j+1 < COLS) ? 2*j+1 : 0)*LBL_W +: LBL_W];
    end
    always @(posedge clk) begin
        lr_we_q  <= row_done && !rst;
        lr_row_q <= l2_row;
        lr_on_q  <= on_l2;
        if (lr_we_q) lr_mem[lr_row_q] <= {lr_on_q, lr_pl};
        if (row_done && l2_row != {ROW_IDX_W{1'b0}})
            fr_mem[l2_row - 1'b1] <= {cont_rec, alias_nx};
    end

    // ---- K: command register (the accumulator update of the step) -------------------------
    localparam [1:0] OP_NONE = 2'd0, OP_NEW = 2'd1, OP_ADD = 2'd2, OP_MERGE = 2'd3;
    reg                 x4_v_q, x4_end_q, x4_last_q;
    reg [1:0]           x4_op_q;
    reg                 x4_mrg_q;             // x4_op_q == OP_MERGE (a step was a merge)
    reg [NL:1]          x4_lp_q, x4_lc_q;     // P's and C's labels after the step
    wire [NL:1]         x4_k = x4_last_q ? (x4_lp_q | x4_lc_q) : (x4_lp_q & ~x4_lc_q);
    reg [ROW_IDX_W-1:0] x4_row_q;
    reg [E_W-1:0]       x4_e_q;                // the run as an entry
    reg [E_W-1:0]       run_e;
    // the second operand of an update: the run (ADD) or label B's entry (MERGE); one
    // combine() serves both
    always @(*) begin
        run_e = {E_W{1'b0}};
        run_e[O_AREA +: AREA_W]    = l2_e_q[F_CNT +: AREA_W];
        run_e[O_SZ +: SZ_W]        = l2_e_q[F_SZ +: SZ_W];
        run_e[O_SX +: SX_W]        = l2_e_q[F_SX +: SX_W];
        run_e[O_SY +: SY_W]        = l2_e_q[F_SY +: SY_W];
        run_e[O_RMIN +: ROW_IDX_W] = l2_row;
        run_e[O_RMAX +: ROW_IDX_W] = l2_row;
        run_e[O_CMIN +: COL_IDX_W] = l2_cmin;
        run_e[O_CMAX +: COL_IDX_W] = l2_e_q[F_CMX +: COL_IDX_W];
        run_e[O_PEAK +: HM_W]      = l2_e_q[F_PK +: HM_W];
        run_e[O_PR +: ROW_IDX_W]   = l2_row;
        run_e[O_PC +: COL_IDX_W]   = l2_e_q[F_PC +: COL_IDX_W];
        run_e[O_FC +: COL_IDX_W]   = l2_cmin;
    end

    // ---- A: accumulators; C: close engine; sorted blob list ---------------------------
    // Two read ports: label A (the updated entry) and a shared one: label B of a MERGE
    // or else the close engine's label (a closed label waits while a MERGE is applied).
    // K reads both (registered), W combines and writes one cycle later; an operand that
    // the update of the cycle before wrote is taken from that update's register.  The
    // memory is split into NAS field slices (a field's update needs its own slice only),
    // each with its own copies of the read and write addresses and of the controls,
    // registered from their next values (the address nets stay inside a slice).
    wire             b_merge = x4_mrg_q;     // (x4_op_q == OP_MERGE)
    reg  [1:0]       w_op_q;
    wire             w_wr  = (w_op_q != OP_NONE);
    // the close engine's next label (lowest pending), picked one cycle ahead
    reg  [LBL_W-1:0] pk_q;
    reg              pk_v_q;
    wire             cl_go   = pk_v_q && !b_merge;
    wire             pk_fill = !pk_v_q || cl_go;
    wire [NL:1]      p_low   = pend_q & (~pend_q + 1'b1);
    reg  [LBL_W-1:0] p_enc;
    reg  [NL:1]      cpick_bit;               // the label the close engine frees
    reg  [NL:1]      p_t;
    always @(*) begin : c_cpick
        integer i, b;
        for (b = 0; b < LBL_W; b = b + 1) begin
            for (i = 1; i <= NL; i = i + 1)
                p_t[i] = p_low[i] && (((i >> b) & 1) == 1);
            p_enc[b] = |p_t;
        end
        for (i = 1; i <= NL; i = i + 1)
            cpick_bit[i] = cl_go && (pk_q == i[LBL_W-1:0]);
    end
    // next values of pk_q, pk_v_q and of the read addresses (label A; label B of a
    // MERGE, else the close engine's label)
    // (pk_hold kept: the merge flag enters at the last select, not through pk_fill)
    (* keep *) wire  pk_hold;
    assign           pk_hold = rst || (b_merge && pk_v_q);      // = rst || !pk_fill
    wire [LBL_W-1:0] pk_nx  = pk_hold ? pk_q : p_enc;
    wire             pkv_nx = rst ? 1'b0 : (pk_fill ? |pend_q : pk_v_q);
    wire [LBL_W-1:0] ra_nx  = do_merge ? x_q : lrun;
    wire [LBL_W-1:0] rb_nx  = do_merge ? l2_y_q : pk_nx;
    wire             wr_nx  = !rst && (x4_op_q != OP_NONE);  // w_op_q's next: W writes
    wire             nw_nx  = (x4_op_q == OP_NEW);
    // the slices' registers, assembled
    wire [E_W-1:0]   w_x, w_yy, cl_e_q;
    wire [E_W-1:0]   w_res = combine(w_x, w_yy);     // (a NEW writes w_yy: per slice)
    localparam AM_W = (MINC_W > AREA_W) ? MINC_W : AREA_W;
    localparam CFI  = 4;                      // cf_mem labels per copy of the blob test
    localparam NCF  = (NL + CFI - 1) / CFI;
    reg  [NCF:0]     cl_isb_q;                // the blob test of cl_e_q (copy NCF: the list)
    genvar ga, gk;
    generate
        for (ga = 0; ga < NAS; ga = ga + 1) begin : g_acc
            localparam LO = (ga == 0) ? O_AREA : (ga == 1) ? O_SX : (ga == 2) ? O_SY
                          : (ga == 3) ? O_RMIN : O_PEAK;
            localparam HI = (ga == 0) ? O_SX : (ga == 1) ? O_SY : (ga == 2) ? O_RMIN
                          : (ga == 3) ? O_PEAK : E_W;
            localparam SW = HI - LO;
            // distributed RAM (as Yosys maps it for xc5v anyway): read A's register is a
            // flip-flop, not a block RAM's output, in front of combine()'s compares
            (* ram_style = "distributed" *)
            reg  [SW-1:0]    acc_q [0:NL];    // (0: never written, keeps the reads in range)
            reg  [LBL_W-1:0] ra_q, rb_q, wa_q;
            reg              we_q, nw_q, mrg_q, pkv_q, fa_q, fb_q;
            reg  [SW-1:0]    ra_d_q, y_q, wr_q, cl_q;   // read A, operand Y, the update
            // copies (keep: one flip-flop each, not merged by synthesis)
            (* keep *) always @(posedge clk) begin
                ra_q  <= ra_nx;
                rb_q  <= rb_nx;
                mrg_q <= do_merge;
                pkv_q <= pkv_nx;
                we_q  <= wr_nx;
                nw_q  <= nw_nx;
                wa_q  <= ra_q;
            end
            wire [SW-1:0] rd_b = acc_q[rb_q];
            always @(posedge clk) begin
                ra_d_q <= acc_q[ra_q];
                y_q    <= mrg_q ? rd_b : x4_e_q[LO +: SW];
                fa_q   <= we_q && (ra_q == wa_q);
                fb_q   <= we_q && mrg_q && (rb_q == wa_q);
                wr_q   <= nw_q ? w_yy[LO +: SW] : w_res[LO +: SW];
                if (we_q) acc_q[wa_q] <= nw_q ? w_yy[LO +: SW] : w_res[LO +: SW];
                if (pkv_q && !mrg_q) cl_q <= rd_b;          // cl_go
            end
            if (ga == 0) begin : g_isb
                // the closed label's blob test (area >= min-cells of the labelled buffer,
                // mc_p_q), registered with cl_q,
                // in copies: one for the list, one per CFI labels of cf_mem's write data
                wire [AREA_W-1:0] rb_area = rd_b[O_AREA - LO +: AREA_W];
                wire isb_nx = ({{(AM_W-AREA_W){1'b0}}, rb_area}
                               >= {{(AM_W-MINC_W){1'b0}}, mc_p_q});
                for (gk = 0; gk <= NCF; gk = gk + 1) begin : g_k
                    (* keep *) always @(posedge clk) cl_isb_q[gk] <= isb_nx;   // (read after cl_go)
                end
            end
            assign w_x[LO +: SW]     = fa_q ? wr_q : ra_d_q;
            assign w_yy[LO +: SW]    = fb_q ? wr_q : y_q;
            assign cl_e_q[LO +: SW]  = cl_q;
        end
    endgenerate
    reg           cl_v_q;
    reg [ROW_IDX_W-1:0] crow_q [0:NL];        // row at whose end the label was closed (0: unused)
    reg [ROW_IDX_W-1:0] cl_row_q;
    reg [LBL_W-1:0]     cl_lbl_q;
    wire [AREA_W-1:0] cl_area = cl_e_q[O_AREA +: AREA_W];
    wire [IDX_W-1:0]  cl_key  = {cl_e_q[O_RMIN +: ROW_IDX_W], cl_e_q[O_FC +: COL_IDX_W]};
    wire              cl_isblob = cl_isb_q[NCF];
    wire              cl_blob = cl_v_q && cl_isblob;

    // The list holds the sort keys (area, raster index of the first cell) and a slot
    // number per entry; the entries themselves sit in two small distributed RAMs of
    // MB + 1 slots (pe_mem: the sums for the dividers, po_mem: the output fields), one
    // write and one read each.  The MB list slots and spare_q are always a permutation
    // of 0..MB: a closed blob is written to the spare slot and inserted with it; the
    // entry that falls off the end gives its slot back as the spare.
    localparam SL_W = $clog2(MB + 1);
    localparam PE_W = SZ_W + SX_W + SY_W;
    localparam PO_W = AREA_W + 2 * ROW_IDX_W + 2 * COL_IDX_W + HM_W + IDX_W;
    /* verilator lint_off UNUSEDSIGNAL */     // the emission reads the slots only
    wire [MB-1:0]        l_v;
    wire [MB*AREA_W-1:0] l_area;
    wire [MB*IDX_W-1:0]  l_key;
    /* verilator lint_on UNUSEDSIGNAL */
    wire [MB*SL_W-1:0]   l_slots;
    wire [SL_W-1:0]      spare_q;              // the free slot (drop_pay_o, a register)
    // entry i's slot (an array for the indexed reads below)
    wire [SL_W-1:0]      l_slot_q [0:MB-1];
    genvar gs_i;
    generate
        for (gs_i = 0; gs_i < MB; gs_i = gs_i + 1) begin : g_slot
            assign l_slot_q[gs_i] = l_slots[gs_i*SL_W +: SL_W];
        end
    endgenerate
    (* ram_style = "distributed" *)
    reg [PE_W-1:0]   pe_mem [0:MB];
    (* ram_style = "distributed" *)
    reg [PO_W-1:0]   po_mem [0:MB];
    always @(posedge clk) begin
        if (cl_blob) begin
            pe_mem[spare_q] <= {cl_e_q[O_SY +: SY_W], cl_e_q[O_SX +: SX_W], cl_e_q[O_SZ +: SZ_W]};
            po_mem[spare_q] <= {cl_e_q[O_PC +: COL_IDX_W], cl_e_q[O_PR +: ROW_IDX_W],
                                cl_e_q[O_PEAK +: HM_W], cl_e_q[O_CMAX +: COL_IDX_W],
                                cl_e_q[O_CMIN +: COL_IDX_W], cl_e_q[O_RMAX +: ROW_IDX_W],
                                cl_e_q[O_RMIN +: ROW_IDX_W], cl_area};
        end
    end
    // area descending, ties by raster key ascending; the slots are the payloads
    // (reset to 0..MB-1, spare MB); a closed blob is inserted with the spare slot
    fmt_sorted_list #(.K(MB), .KEY_W(AREA_W), .TIE_W(IDX_W), .PAY_W(SL_W), .PAY_RST_IDX(1),
                      .HAS_POP(0)) u_list (
        .clk(clk), .rst(rst), .clear_i(releasing),
        .ins_i(cl_blob), .ins_key_i(cl_area), .ins_tie_i(cl_key), .ins_pay_i(spare_q),
        .nxt_key_i({AREA_W{1'b0}}), .nxt_tie_i({IDX_W{1'b0}}), .ins_ahead_i(1'b0),
        .pop_i(1'b0), .valid_o(l_v), .key_o(l_area), .tie_o(l_key), .pay_o(l_slots),
        .drop_pay_o(spare_q));
    reg [AREA_W-1:0] found_q;
    reg              lab_done_q;              // the last row's command has been applied

    // ---- emission -----------------------------------------------------------------------
    reg [CNT_W-1:0]   em_i_q, em_n_q;
    reg               em_ph_q;                // 0: x quotients of entries 0..n-1, 1: y
    reg [FRAME_W-1:0] em_frame_q;
    reg               em_incomplete_q, em_over_q;
    reg [AREA_W-1:0]  em_found_q;
    wire              em_issue = (state_q == S_EMIT) && (em_i_q != em_n_q);
    wire              em_tok   = (state_q == S_EMIT) && (em_i_q == em_n_q);
    // the sums of list entry em_i_q (an index >= MB reads entry 0): the slot registered
    // (EA), the sums read and the numerator registered (EB), then the divider
    wire [SL_W-1:0]  em_slot = (em_i_q < MB_C) ? l_slot_q[em_i_q[MBI_W-1:0]] : l_slot_q[0];
    reg  [SL_W-1:0]  ea_slot_q;
    reg              ea_v_q, ea_ph_q, eb_v_q;
    reg  [NUM_W-1:0] eb_num_q;
    reg  [SZ_W-1:0]  eb_den_q;
    wire [PE_W-1:0]  em_p    = pe_mem[ea_slot_q];
    wire [SZ_W-1:0]  em_sz   = em_p[0 +: SZ_W];
    wire [SX_W-1:0]  em_sx   = em_p[SZ_W +: SX_W];
    wire [SY_W-1:0]  em_sy   = em_p[SZ_W + SX_W +: SY_W];
    wire [NUM_W-1:0] num_x = {{(NUM_W-SX_W-8){1'b0}}, em_sx, 8'd0}
                           + {{(NUM_W-SZ_W+1){1'b0}}, em_sz[SZ_W-1:1]};
    wire [NUM_W-1:0] num_y = {{(NUM_W-SY_W-8){1'b0}}, em_sy, 8'd0}
                           + {{(NUM_W-SZ_W+1){1'b0}}, em_sz[SZ_W-1:1]};
    // One divider for both coordinates: the x quotients of the n list entries are
    // issued first, then the y quotients; an x result waits in qx_q (indexed by the
    // entry) for its y result, which comes n cycles later, so the blobs still leave on
    // consecutive cycles.  valid_o duplicates dl_v_q | dl_x_q; ovf_o needs sum z = 0
    // (threshold 0, unsupported; the quotient is then all ones).
    /* verilator lint_off UNUSEDSIGNAL */
    wire          dq_v, dq_ovf;
    /* verilator lint_on UNUSEDSIGNAL */
    wire [QW-1:0] dq;
    fmt_div #(.NUM_W(NUM_W), .DEN_W(SZ_W), .QW(QW)) u_div (
        .clk(clk), .rst(rst), .valid_i(eb_v_q), .num_i(eb_num_q),
        .den_i(eb_den_q), .valid_o(dq_v), .quot_o(dq), .ovf_o(dq_ovf));
    always @(posedge clk) begin
        ea_slot_q <= em_slot;
        ea_ph_q   <= em_ph_q;
        ea_v_q    <= em_issue && !rst;
        eb_num_q  <= ea_ph_q ? num_y : num_x;
        eb_den_q  <= em_sz;
        eb_v_q    <= ea_v_q && !rst;
    end
    // index, phase and end token travel beside the divider
    reg [DL-1:0]       dl_v_q, dl_x_q, dl_t_q;
    reg [CNT_W-1:0]    dl_i_q [0:DL-1];
    reg [QW-1:0]       qx_q [0:MB-1];         // x quotient per list entry
    wire               out_x   = dl_x_q[DL-1];
    wire               out_v   = dl_v_q[DL-1];
    wire               out_tok = dl_t_q[DL-1];
    wire [CNT_W-1:0]   out_i   = dl_i_q[DL-1];
    wire [SL_W-1:0]    out_slot = (out_i < MB_C) ? l_slot_q[out_i[MBI_W-1:0]] : l_slot_q[0];
    wire [PO_W-1:0]    out_p    = po_mem[out_slot];

    // ---- M: membership pass, rows ROWS-1 down to 0, one per cycle ---------------------
    // A label of row r (labels at the row's end: the connected parts of the regions
    // within rows 0..r) that continued into row r+1 as label a has the status of a in
    // row r+1 (sn_q, the previous step); otherwise its region ended with row r and was
    // closed at the end of row r+1 (the last row's labels: at its own end), and cf_mem
    // (per label, by row) holds whether it was a blob.
    reg                  bw_run_q;            // reading rows
    reg [ROW_IDX_W-1:0]  bw_r_q;              // next row to read
    reg                  bw_v1_q, bw_v_q;     // block-RAM read of row bw_row1_q / bw_row_q
    reg [ROW_IDX_W-1:0]  bw_row1_q, bw_row_q;
    reg [NL*(LBL_W+1)-1:0] fr_rd1_q, fr_rd_q; // continuation record of row r
    reg [LR_W-1:0]       lr_rd1_q, lr_rd_q;   // on-cells and pair labels of row r
    reg [NL:1]           sn_q;                // status (blob) of the labels of row r+1
    reg                  mask_ok_q;           // the mask holds a complete frame
    reg                  bw_busy_q;           // the frame's membership pass is not done
    reg                  tok_q;               // the frame's blob_eof went out
    always @(posedge clk) begin
        fr_rd1_q <= fr_mem[bw_r_q];           // (read every cycle: used only while
        lr_rd1_q <= lr_mem[bw_r_q];           //  bw_v_q, no enable net of ~550 loads)
        fr_rd_q <= fr_rd1_q;                  // the block RAMs' output registers
        lr_rd_q <= lr_rd1_q;
    end
    wire                 bw_first = (bw_row_q == LAST_ROW);
    // Close records: per row r a word of NL fields of CFB bits, field l-1 all set when
    // label l closed at the end of row r was a blob (written by the close engine, one
    // field per cycle: block RAM with byte enables, no read-modify-write); read for the
    // row bw_first ? LAST_ROW : bw_row_q + 1 in two registered steps beside fr_mem, the
    // address from bw_r_q
    localparam CFB = 8;                       // bits per label field: one byte enable
    wire [ROW_IDX_W-1:0] cf_row_nx = (bw_r_q == LAST_ROW) ? LAST_ROW : bw_r_q + 1'b1;
    (* ram_style = "block", no_rw_check *)    // (written while labelling, read in the pass)
    reg  [NL*CFB-1:0]    cf_mem [0:ROWS-1];
    /* verilator lint_off UNUSEDSIGNAL */     // a field's bits beyond the first
    reg  [NL*CFB-1:0]    cf_rd1_q;
    /* verilator lint_on UNUSEDSIGNAL */
    reg  [NL:1]          cf_rd_q;
    always @(posedge clk) begin : s_cf
        integer l;
        for (l = 1; l <= NL; l = l + 1)
            if (cl_v_q && cl_lbl_q == l[LBL_W-1:0])
                cf_mem[cl_row_q][(l-1)*CFB +: CFB] <= {CFB{cl_isb_q[(l-1)/CFI]}};
        cf_rd1_q <= cf_mem[cf_row_nx];        // with fr_rd1_q (row bw_r_q)
        for (l = 1; l <= NL; l = l + 1)
            cf_rd_q[l] <= cf_rd1_q[(l-1)*CFB]; // the output register, with fr_rd_q
    end
    wire [NL:1]          cfr;
    genvar gl;
    generate
        for (gl = 1; gl <= NL; gl = gl + 1) begin : g_cf
            assign cfr[gl] = cf_rd_q[gl];
        end
    endgenerate
    // status of the labels of row r: an indexed select (one 2^LBL_W : 1 multiplexer)
    // per label; the padded vector returns 0 for label 0 and for codes above NL, and
    // bw_s keeps the close record when a code is outside 1..NL.
    localparam NLP = 1 << LBL_W;
    localparam integer NL_I = NL;
    localparam [LBL_W-1:0] NL_L = NL_I[LBL_W-1:0];
    reg [NL:1]      bw_s;
    reg [LBL_W-1:0] la_r;
    reg [NLP-1:0]   sn_pad;
    always @(*) begin : c_bw_s
        integer g;
        sn_pad = {NLP{1'b0}};
        sn_pad[NL:1] = sn_q;
        for (g = 1; g <= NL; g = g + 1) begin
            la_r = fr_rd_q[(g-1)*LBL_W +: LBL_W];
            if (!bw_first && fr_rd_q[NL*LBL_W + g - 1] &&
                la_r != {LBL_W{1'b0}} && la_r <= NL_L)
                bw_s[g] = sn_pad[la_r];
            else
                bw_s[g] = cfr[g];
        end
    end
    // the cells of row r: the status of their label (MK), a row of the mask
    reg                  mk_v_q;
    reg [ROW_IDX_W-1:0]  mk_row_q;
    reg [NL:1]           mk_s_q;
    reg [LR_W-1:0]       mk_lr_q;
    reg [NLP-1:0]        mk_s_pad;
    reg [COLS-1:0]       mk_on, mk_st;
    always @(*) begin : c_mk
        integer c;
        mk_s_pad = {NLP{1'b0}};
        mk_s_pad[NL:1] = mk_s_q;
        mk_on = mk_lr_q[NPR*LBL_W +: COLS];
        for (c = 0; c < COLS; c = c + 1)
            mk_st[c] = mk_on[c] && (c == 0 || !mk_on[(c > 0) ? c - 1 : 0])
                    && mk_s_pad[mk_lr_q[(c/2)*LBL_W +: LBL_W]];
    end
    // the mask row is stored as its on-cells and its blob run starts (the status select
    // and the fill's carry chain in different cycles); the query fills the row it reads
    (* ram_style = "distributed" *)
    reg [2*COLS-1:0]     mask_mem [0:ROWS-1];
    always @(posedge clk) begin
        if (mk_v_q) mask_mem[mk_row_q] <= {mk_st, mk_on};
        mk_s_q   <= bw_s;
        mk_lr_q  <= lr_rd_q;
        mk_row_q <= bw_row_q;
    end

    // ---- Q: cell query: the row's mask word, then the cell's bit -----------------------
    localparam NCP = 1 << COL_IDX_W;
    reg [COLS-1:0]       q_w_q;               // mask word of the queried row
    reg [COL_IDX_W-1:0]  q_col_q;
    reg [NCP-1:0]        q_w_pad;             // columns >= COLS read 0
    wire [2*COLS-1:0]    q_rd = mask_mem[mask_q_row_i];
    /* verilator lint_off UNUSEDSIGNAL */     // q_fill[COLS]: a carry beyond the last column
    wire [COLS:0]        q_fill = {1'b0, q_rd[0 +: COLS]} + {1'b0, q_rd[COLS +: COLS]};
    /* verilator lint_on UNUSEDSIGNAL */
    always @(posedge clk) begin
        // a run's cells get the status of its label, from its start: the status bit added
        // at the start carries through the run (its cells become 0) and stops after it
        q_w_q   <= q_rd[0 +: COLS] & ~q_fill[COLS-1:0];
        q_col_q <= mask_q_col_i;
    end
    always @(*) begin
        q_w_pad = {NCP{1'b0}};
        q_w_pad[COLS-1:0] = q_w_q;
    end

    wire pipe_busy = f1_v_q || f2_v_q || e1_v_q || x1_v_q || x2_v_q || x3_v_q || y4_v_q
                   || y5_v_q || (fcnt_q != {(FP_W+1){1'b0}}) || l0_v_q || lg_v_q || l1_v_q || l2_v_q || x4_v_q
                   || w_wr || cl_v_q || (|pend_q) || pk_v_q;
    reg  idle_q;                              // the pipeline was idle (one cycle late)
    wire complete  = (arr_p == {ROWS{1'b1}});
    wire fin_ok    = (state_q == S_RUN) && eofs_q[pb_q] && lab_done_q && idle_q;
    reg  abort_q;                             // incomplete frame, pipeline idle (one cycle late)
    wire fin_abort = (state_q == S_RUN) && abort_q;
    assign releasing = (state_q == S_WAIT) && (out_tok || tok_q) && !bw_busy_q;
    // av_q's next value: in S_RUN (not finishing) row fr_q or, after a fetch, fr_q + 1 of
    // bank pb_q; after the release row 0 of the other bank; the arrivals of this cycle
    // counted (both candidates looked up beside fetch, which only picks one)
    // (by the one-hot fr_oh_q: an AND-OR over the rows in groups of 3, no index select;
    // this cycle's row by one compare with fr_q, fr1_q = fr_q + 1; the parts are kept
    // wires, so synthesis maps a balanced tree and not a LUT chain: 11 xc5v levels else)
    localparam AVG = (ROWS + 2) / 3;
    wire                 arr_o0  = pb_q ? arr_q[0][0] : arr_q[1][0];   // the other bank's row 0
    wire                 hm_p    = hm_valid_i && (wb_q == pb_q);
    wire                 fr1_in  = (fr1_q < ROWS_R);
    reg  [3*AVG-1:0]     av_ap, av_o0, av_o1;
    reg  [AVG-1:0]       av_s0, av_s1;
    always @(*) begin : c_av_g
        integer j;
        av_ap = {(3*AVG){1'b0}};
        av_o0 = {(3*AVG){1'b0}};
        av_o1 = {(3*AVG){1'b0}};
        av_ap[ROWS-1:0] = arr_p;
        av_o0[ROWS-1:0] = fr_oh_q;
        av_o1[ROWS-1:0] = {fr_oh_q[ROWS-2:0], 1'b0};
        for (j = 0; j < AVG; j = j + 1) begin
            av_s0[j] = |(av_ap[3*j +: 3] & av_o0[3*j +: 3]);
            av_s1[j] = |(av_ap[3*j +: 3] & av_o1[3*j +: 3]);
        end
    end
    // (kept wires; assigned below)
    (* keep *) wire [AVG-1:0] av_g0;           // row fr_q arrived (per group of 3 rows)
    (* keep *) wire [AVG-1:0] av_g1;           // row fr_q + 1
    (* keep *) wire           av_h0, av_h1;    // ... arriving this cycle
    (* keep *) wire           av_a0, av_a1;    // row fr_q, fr_q + 1 present next cycle
    (* keep *) wire           av_run, av_rel;  // S_RUN stays; the release
    assign av_g0  = av_s0;
    assign av_g1  = av_s1;
    assign av_h0  = hm_p && fr_in && (hm_row_i == fr_row);
    assign av_h1  = hm_p && fr1_in && (hm_row_i == fr1_q[ROW_IDX_W-1:0]);
    assign av_a0  = (|av_g0) || av_h0;
    assign av_a1  = (|av_g1) || av_h1;
    assign av_run = !rst && (state_q == S_RUN) && !fin_ok && !fin_abort;
    assign av_rel = !rst && releasing && (arr_o0 || (hm_valid_i && (wb_q != pb_q)
                                                     && hm_row_i == {ROW_IDX_W{1'b0}}));
    assign               av_nx   = (av_run && (fetch ? av_a1 : av_a0)) || av_rel;
    always @(posedge clk) av_q <= av_nx;
    // synthesis translate_off
    reg chk_rst_q;                            // a reset was seen (the checks below after it)
    initial chk_rst_q = 1'b0;
    always @(posedge clk) if (rst) chk_rst_q <= 1'b1;
    always @(posedge clk) begin
        if (!rst && chk_rst_q && (av_q !== ((state_q == S_RUN) && fr_in && arr_p[fr_row])
                     || fr_oh_q !== (fr_in ? {{(ROWS-1){1'b0}}, 1'b1} << fr_row : {ROWS{1'b0}})
                     || fr1_q !== fr_q + 1'b1
                     || avc_q !== {NG{av_q}} || f1vc_q !== {NG{f1_v_q}} || f2vc_q !== {NG{f2_v_q}})) begin
            $display("fmt_blob: av_q %b or an enable copy differs (fr_oh_q %h fr_q %0d) at %0t", av_q, fr_oh_q, fr_q, $time);
            $finish;
        end
    end
    // synthesis translate_on
    wire over      = (found_q > MB_A);

    always @(posedge clk) begin : s_main
        integer i;
        // ---- datapath registers (no reset needed) ----
        // (E's and F2's column registers: per GS columns in g_mem)
        if (f2_take)
            e1_row_q <= f2_row_q;
        if (f2_take) begin
            e1_last_q <= f2_one_q;
            e1_first_q <= 1'b1;
        end else if (ev_go) begin
            e1_last_q <= le2(e1_rem_q);             // = ((e1_remr & ~e1_neg) == 0): b is in rem
            e1_first_q <= 1'b0;
        end
        x1_f_q   <= {e1_row_q == LAST_ROW, e1_first_q, ev_last, 1'b0, ev_run};
        x1_m_q   <= ev_m;
        x1_lc_q  <= ev_lc;
        for (i = 0; i < COLS; i = i + 1)
            x1_z_q[i*HM_W +: HM_W] <= ev_m[i] ? e1_z_q[i*HM_W +: HM_W] : {HM_W{1'b0}};
        x1_row_q <= e1_row_q;
        x2_f_q <= x1_f_q | {3'b000, |x1_lc_q, 1'b0};  x2_lc_q <= lc_enc;  x2_row_q <= x1_row_q;
        x2_gs_q <= gs;  x2_gx_q <= gx;  x2_pk_q <= pk1[PN1*PK_W-1:0];
        x2_cmin_q <= cmin;  x2_cmax_q <= cmax;
        x3_f_q <= x2_f_q;  x3_lc_q <= x2_lc_q;  x3_row_q <= x2_row_q;
        x3_cnt_q <= {{(AREA_W-COL_IDX_W){1'b0}}, x2_cmax_q - x2_cmin_q} + 1'b1;  x3_cmin_q <= x2_cmin_q;  x3_cmax_q <= x2_cmax_q;
        x3_s_q <= tr_s[SZ_W-1:0];  x3_gx_q <= tr_g[GXT_W-1:0];  x3_gt_q <= gt;  x3_pk_q <= pk3[PN3*PK_W-1:0];
        y4_e_q <= x3_ev;  y4_pk_q <= pk5[PN5*PK_W-1:0];  y4_ylo_q <= ylo;  y4_yhi_q <= yhi;
        y4_sx_q <= sx4;
        y5_e_q <= y4_ev;
        // the stages' wide registers: enables from the copies of adv, in ranges
        for (i = 0; i < FE_W; i = i + 1) begin
            if (advc_q[(i * 2) / FE_W])     l0_e_q[i] <= f_rd[i];
            if (advc_q[2 + (i * 3) / FE_W]) lg_e_q[i] <= l0_e_q[i];
            if (advc_q[5 + (i * 3) / FE_W]) l1_e_q[i] <= lg_e_q[i];
            if (advc_q[8 + (i * 3) / FE_W]) l2_e_q[i] <= l1_e_q[i];
        end
        for (i = 0; i < COLS; i = i + 1) begin
            if (advc_q[1])  l0_oh_q[i] <= lc_oh[i];
            if (advc_q[4])  lg_oh_q[i] <= l0_oh_q[i];
            if (advc_q[6])  l1_oh_q[i] <= lg_oh_q[i];
            if (advc_q[7])  l1_m_q[i]  <= l1_m[i];
            if (advc_q[10]) l2_m_q[i]  <= l1_m_q[i];
        end
        if (adv) begin                        // (LG, L1 hold only while L2 waits: no step)
            l1_ov_q <= |(lg_oh_q & l1_m_q);
            l1_mg_q <= lg_v_q && !lg_f[0] && lg_f[1];
            l1_sv_q <= eqg;
            lg_yg_q <= y0g;
            lg_hp_q <= l0_hp;
            l1_y_q  <= yga;
            l1_hp_q <= lg_hp;
            l2_y_q  <= y1;
        end else begin                        // (held: the pending step applied now)
            lg_yg_q <= yga_g;
            lg_hp_q <= 1'b0;
            l1_y_q  <= ya;
            l1_sv_q <= eqa;                   // (ya == l2_y_q)
            l1_hp_q <= 1'b0;
        end
        s_mrg_q  <= do_merge;
        s_run_q  <= do_run;
        s_v_q    <= l2_y_q;
        s_x_q    <= x_q;
        s_lrun_q <= lrun;
        if (do_run) x_q <= lrun;
        // (reset: the step registers before it are reset one cycle late for this one)
        x4_op_q  <= rst ? OP_NONE : (do_merge ? OP_MERGE : (do_new ? OP_NEW
                                  : (do_run ? OP_ADD : OP_NONE)));
        x4_mrg_q <= do_merge && !rst;
        x4_e_q   <= run_e;
        x4_row_q <= l2_row;
        x4_end_q <= row_done;
        x4_last_q <= row_done && l2_lastrow;
        x4_lp_q  <= livep_nx;
        x4_lc_q  <= livec_nx;
        // accumulators: K reads (label A, and label B of a MERGE), W combines and writes
        w_op_q  <= x4_op_q;                   // (OP_NONE when no step)
        pk_q    <= pk_nx;
        if (cl_go) begin
            cl_row_q <= crow_q[pk_q];
            cl_lbl_q <= pk_q;
        end
        if (x4_v_q && x4_end_q) begin
            for (i = 1; i <= NL; i = i + 1)
                if (x4_k[i]) crow_q[i] <= x4_row_q;
        end
        // emission side registers
        dl_i_q[0] <= em_i_q;

        for (i = 1; i < DL; i = i + 1) dl_i_q[i] <= dl_i_q[i-1];
        blob_area_o     <= out_p[0 +: AREA_W];
        if (out_x) qx_q[out_i[MBI_W-1:0]] <= dq;
        blob_cx_o       <= {{(16-QW){1'b0}}, qx_q[out_i[MBI_W-1:0]]};
        blob_cy_o       <= {{(16-QW){1'b0}}, dq};
        blob_rmin_o     <= out_p[AREA_W +: ROW_IDX_W];
        blob_rmax_o     <= out_p[AREA_W + ROW_IDX_W +: ROW_IDX_W];
        blob_cmin_o     <= out_p[AREA_W + 2*ROW_IDX_W +: COL_IDX_W];
        blob_cmax_o     <= out_p[AREA_W + 2*ROW_IDX_W + COL_IDX_W +: COL_IDX_W];
        blob_peak_o     <= out_p[AREA_W + 2*ROW_IDX_W + 2*COL_IDX_W +: HM_W];
        blob_peak_row_o <= out_p[AREA_W + 2*ROW_IDX_W + 2*COL_IDX_W + HM_W +: ROW_IDX_W];
        blob_peak_col_o <= out_p[AREA_W + 3*ROW_IDX_W + 2*COL_IDX_W + HM_W +: COL_IDX_W];
        blob_frame_o    <= em_frame_q;

        if (rst) begin
            arr_q[0] <= {ROWS{1'b0}};
            arr_q[1] <= {ROWS{1'b0}};
            eofs_q   <= 2'b00;
            wb_q     <= 1'b0;
            pb_q     <= 1'b0;
            state_q  <= S_RUN;
            fr_q     <= {(ROW_IDX_W+1){1'b0}};
            fr_oh_q  <= {{(ROWS-1){1'b0}}, 1'b1};
            fr1_q    <= {{ROW_IDX_W{1'b0}}, 1'b1};
            lastc_q  <= {COLS{1'b0}};
            f1_v_q   <= 1'b0;
            f2_v_q   <= 1'b0;
            e1_v_q   <= 1'b0;
            y4_v_q   <= 1'b0;
            y5_v_q   <= 1'b0;
            fwp_q    <= {FP_W{1'b0}};
            frp_q    <= {FP_W{1'b0}};
            fcnt_q   <= {(FP_W+1){1'b0}};
            res_q    <= {(FP_W+1){1'b0}};
            l0_v_q   <= 1'b0;
            lg_v_q   <= 1'b0;
            l1_mg_q  <= 1'b0;
            l1_v_q   <= 1'b0;
            l2_v_q   <= 1'b0;
            n0v_q    <= 1'b0;
            s_mrg_q  <= 1'b0;
            s_run_q  <= 1'b0;
            pk_v_q   <= 1'b0;
            idle_q   <= 1'b0;
            abort_q  <= 1'b0;
            free_q   <= {NL{1'b1}};
            pend_q   <= {NL{1'b0}};
            x1_v_q   <= 1'b0;
            x2_v_q   <= 1'b0;
            x3_v_q   <= 1'b0;
            x4_v_q   <= 1'b0;
            w_op_q   <= OP_NONE;
            cl_v_q   <= 1'b0;
            found_q  <= {AREA_W{1'b0}};
            lab_done_q <= 1'b0;
            em_i_q   <= {CNT_W{1'b0}};
            em_ph_q  <= 1'b0;
            em_n_q   <= {CNT_W{1'b0}};
            em_frame_q <= {FRAME_W{1'b0}};
            em_incomplete_q <= 1'b0;
            em_over_q  <= 1'b0;
            em_found_q <= {AREA_W{1'b0}};
            dl_v_q   <= {DL{1'b0}};
            dl_x_q   <= {DL{1'b0}};
            dl_t_q   <= {DL{1'b0}};
            bw_run_q  <= 1'b0;
            bw_r_q    <= {ROW_IDX_W{1'b0}};
            bw_v1_q   <= 1'b0;
            bw_v_q    <= 1'b0;
            mk_v_q    <= 1'b0;
            bw_busy_q <= 1'b0;
            tok_q     <= 1'b0;
            mask_ok_q <= 1'b0;
            mask_q_data_o <= 1'b0;
            mask_ready_o <= 1'b0;
            mask_frame_o <= {FRAME_W{1'b0}};
            blob_valid_o      <= 1'b0;
            blob_eof_o        <= 1'b0;
            blob_count_o      <= {CNT_W{1'b0}};
            blob_found_o      <= {AREA_W{1'b0}};
            blob_overflow_o   <= 1'b0;
            blob_incomplete_o <= 1'b0;
            overflow_flag_o   <= 1'b0;
            overrun_o         <= 1'b0;
        end else begin
            // ---- arrivals ----
            if (hm_valid_i) arr_q[wb_q][hm_row_i] <= 1'b1;
            if (hm_eof_i) begin
                eofs_q[wb_q] <= 1'b1;
                frm_q[wb_q]  <= hm_frame_i;
                wb_q         <= ~wb_q;
                if (pb_q != wb_q && !releasing) overrun_o <= 1'b1;
            end

            // ---- fetch, extraction, sums, FIFO ----
            if (fetch) fr_q <= fr_q + 1'b1;
            if (fetch) fr_oh_q <= {fr_oh_q[ROWS-2:0], 1'b0};
            if (fetch) fr1_q <= fr1_q + 1'b1;
            if (fetch) lastc_q <= on_f;
            if (fetch) f1_v_q <= 1'b1;
            else if (f1_mv) f1_v_q <= 1'b0;
            if (f1_mv) f2_v_q <= 1'b1;
            else if (f2_take) f2_v_q <= 1'b0;
            if (f2_take) e1_v_q <= 1'b1;
            else if (ev_go && ev_last) e1_v_q <= 1'b0;
            x1_v_q <= ev_go;
            x2_v_q <= x1_v_q;
            x3_v_q <= x2_v_q;
            y4_v_q <= x3_v_q;
            y5_v_q <= y4_v_q;
            if (y5_v_q) fwp_q <= fwp_q + 1'b1;
            if (fpop)   frp_q <= frp_q + 1'b1;
            fcnt_q <= fcnt_q + {{FP_W{1'b0}}, y5_v_q} - {{FP_W{1'b0}}, fpop};
            res_q  <= res_q + {{FP_W{1'b0}}, ev_go} - {{FP_W{1'b0}}, fpop};
            if (adv) begin
                l0_v_q <= fpop;
                lg_v_q <= l0_v_q;
                l1_v_q <= lg_v_q;
            end
            if (l2_ld) l2_v_q <= 1'b1;
            else if (step) l2_v_q <= 1'b0;

            // ---- labelling state ----
            // at a row end P = C (0 after the last row; C kept: the next row's first
            // event reads it), the live masks move; the row-end copies per group
            for (i = 1; i <= NL; i = i + 1)
                alias_q[(i-1)*LBL_W +: LBL_W] <= rdc_q[NG + (i-1)/ALG] ? alias_id[(i-1)*LBL_W +: LBL_W]
                                                                     : alias_nx[(i-1)*LBL_W +: LBL_W];
            for (i = 0; i < COLS; i = i + 1)
                p_q[i*LBL_W +: LBL_W] <= !rdc_q[i/GS] ? p_nx[i*LBL_W +: LBL_W]
                                       : (l2_lastrow ? {LBL_W{1'b0}} : c_nx[i*LBL_W +: LBL_W]);
            c_q <= c_nx;
            if (rdc_q[VC]) begin
                livep_q <= l2_lastrow ? {NL{1'b0}} : livec_nx;
                livec_q <= {NL{1'b0}};
            end else begin
                livep_q <= livep_nx;
                livec_q <= livec_nx;
            end
            if (n0_fill) begin
                n0_q  <= f_enc;
                n0v_q <= |free_q;
            end
            free_q <= (free_q & ~(n0_fill ? f_low : {NL{1'b0}}))
                    | (dmc_q[VC] ? vbit : {NL{1'b0}})
                    | cpick_bit;
            x4_v_q <= do_merge || do_run || row_done;
            pend_q <= (pend_q & ~(pk_fill ? p_low : {NL{1'b0}}))
                    | ((x4_v_q && x4_end_q) ? x4_k : {NL{1'b0}});
            if (pk_fill) pk_v_q <= |pend_q;     // (pk_q <= pk_nx above)
            idle_q <= !pipe_busy && !fetch;
            abort_q <= (state_q == S_RUN) && eofs_q[pb_q] && !lab_done_q && !pipe_busy
                     && !fetch && fr_in && !av_q && !releasing;
            if (x4_v_q && x4_last_q) lab_done_q <= 1'b1;
            cl_v_q <= cl_go;

            // ---- a closed blob: counted (u_list inserts it) ----
            if (cl_blob && found_q != {AREA_W{1'b1}}) found_q <= found_q + 1'b1;

            // ---- finish, emit, release ----
            if (fin_ok || fin_abort) begin
                state_q         <= S_EMIT;
                em_i_q          <= {CNT_W{1'b0}};
                em_ph_q         <= 1'b0;
                em_n_q          <= (fin_ok && complete) ? (over ? MB_A[CNT_W-1:0] : found_q[CNT_W-1:0])
                                                        : {CNT_W{1'b0}};
                em_frame_q      <= frm_q[pb_q];
                em_incomplete_q <= !(fin_ok && complete);
                em_over_q       <= fin_ok && complete && over;
                em_found_q      <= (fin_ok && complete) ? found_q : {AREA_W{1'b0}};
            end
            // membership pass (complete frames), in parallel with the emission
            mask_ready_o <= 1'b0;
            if (fin_ok) begin
                bw_run_q  <= 1'b1;
                bw_r_q    <= LAST_ROW;
                bw_busy_q <= 1'b1;
                mask_ok_q <= 1'b0;
            end
            mask_q_data_o <= q_w_pad[q_col_q] && mask_ok_q;
            if (fin_abort) begin
                mask_ready_o <= 1'b1;
                mask_frame_o <= frm_q[pb_q];
                mask_ok_q    <= 1'b0;
            end
            bw_v1_q   <= bw_run_q;
            bw_row1_q <= bw_r_q;
            bw_v_q    <= bw_v1_q;
            bw_row_q  <= bw_row1_q;
            mk_v_q    <= bw_v_q;
            if (bw_run_q) begin
                if (bw_r_q == {ROW_IDX_W{1'b0}}) bw_run_q <= 1'b0;
                else                             bw_r_q   <= bw_r_q - 1'b1;
            end
            if (bw_v_q) sn_q <= bw_s;
            if (mk_v_q) begin
                if (mk_row_q == {ROW_IDX_W{1'b0}}) begin
                    bw_busy_q    <= 1'b0;
                    mask_ready_o <= 1'b1;
                    mask_frame_o <= em_frame_q;
                    mask_ok_q    <= 1'b1;
                end
            end
            if (out_tok) tok_q <= 1'b1;

            if (em_tok) state_q <= S_WAIT;
            if (em_issue) begin
                if (!em_ph_q && em_i_q + 1'b1 == em_n_q) begin
                    em_i_q  <= {CNT_W{1'b0}};     // x quotients issued: now the y ones
                    em_ph_q <= 1'b1;
                end else begin
                    em_i_q  <= em_i_q + 1'b1;
                end
            end
            dl_v_q <= {dl_v_q[DL-2:0], em_issue && em_ph_q};
            dl_x_q <= {dl_x_q[DL-2:0], em_issue && !em_ph_q};
            dl_t_q <= {dl_t_q[DL-2:0], em_tok};
            blob_valid_o <= out_v;
            blob_eof_o   <= out_tok;
            if (out_tok) begin
                blob_count_o      <= em_n_q;
                blob_found_o      <= em_found_q;
                blob_overflow_o   <= em_over_q;
                blob_incomplete_o <= em_incomplete_q;
                if (em_over_q) overflow_flag_o <= 1'b1;
            end
            if (releasing) begin
                state_q      <= S_RUN;
                tok_q        <= 1'b0;         // u_list is cleared
                found_q      <= {AREA_W{1'b0}};
                lab_done_q   <= 1'b0;
                fr_q         <= {(ROW_IDX_W+1){1'b0}};
                fr_oh_q      <= {{(ROWS-1){1'b0}}, 1'b1};
                fr1_q        <= {{ROW_IDX_W{1'b0}}, 1'b1};
                lastc_q      <= {COLS{1'b0}};
                arr_q[pb_q]  <= {ROWS{1'b0}};
                eofs_q[pb_q] <= 1'b0;
                pb_q         <= ~pb_q;
                // an aborted frame leaves labels behind: start clean (P, C, the live
                // masks and alias by clrc_q, one cycle later)
                free_q  <= {NL{1'b1}};
                n0v_q   <= 1'b0;
            end
        end
        // the label vectors cleared one cycle after a reset or a release (no event is
        // in L0..L2 then, nor in the cycle after), by registered copies per GS columns,
        // per alias group and for the live masks
        for (i = 0; i < COLS; i = i + 1)
            if (clrc_q[i/GS]) begin
                p_q[i*LBL_W +: LBL_W] <= {LBL_W{1'b0}};
                c_q[i*LBL_W +: LBL_W] <= {LBL_W{1'b0}};
            end
        for (i = 1; i <= NL; i = i + 1)
            if (clrc_q[NG + (i-1)/ALG]) alias_q[(i-1)*LBL_W +: LBL_W] <= alias_id[(i-1)*LBL_W +: LBL_W];
        if (clrc_q[VC]) begin
            livep_q <= {NL{1'b0}};
            livec_q <= {NL{1'b0}};
        end
    end

endmodule

`default_nettype wire
