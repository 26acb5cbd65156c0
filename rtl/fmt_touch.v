// fmt_touch -- the touch-processing top: heat-map stream in, touch-event stream out.
//
//   fmt_flatten -> fmt_localmax -> fmt_interp -> [finger removal] -> fmt_tracker
//               -> fmt_blob ----------------------------------------> [blob events]
//                                                             -> fmt_event_port
//
// Blobs (blob_en_i = 1; twin process_frames(blobs=True)): fmt_blob sees the flattened
// stream beside fmt_localmax.  The frame's fine touches (fmt_interp keeps the order of
// the candidates, so the candidate cells are kept in a buffer of MAX_TOUCHES entries
// beside the touch beats) are held until the blob mask of the frame is written
// (mask_ready), then replayed one per cycle: the candidate cell is queried (fmt_blob's
// cell query port, 2 cycles), then the touch goes to the tracker unless its candidate
// cell lies in a blob (all blobs, also beyond the 8 reported); tp_eof follows on the
// next cycle.  Up to 8 blob
// records are buffered and emitted after the tracker's events of the frame (when the
// tracker is idle again) as type 3: id 0xFF, x/y = centroid (Q8.8), strength = peak,
// axes/angle/flags 0, ev_last on the last blob.  blob_threshold_i must be >= 1.
// With blob_en_i = 0 the blob path is bypassed combinationally: the events and their
// timing are those of the chain without blobs.  The blob path handles one frame at a
// time (the frame's events must be out before the next frame's touches: true at the
// frame period, ~100 cycles against >= 384).  The event port reserves room for
// 2 * MAX_TOUCHES + 8 events per frame.
// Extra latency with blobs on: the wait for the mask (~56..61 cycles after the last
// row beat at 30 x 40), n + 3 cycles of replay, then one cycle per blob event.
// Measured (tb/fmt_touch, test blobs): last row beat -> last event 54..63 cycles on
// 8 x 10 palm scenes (1..4 events), worst 101 on random maps with many blobs; at
// 30 x 40 81..108 cycles on palm scenes, worst 377 on random maps.
//
// Twin: sim/fmt/touch.py process_frames(fixed=True, blobs=False): per frame the same
// events in the same order (time stamps excepted).
//
// Run-time settings (input ports, driven by the core's register file) may change in
// any cycle: every frame is processed with the values present in the cycle its first
// heat-map row enters (twin: process_frames(frame_settings=...)), in every stage, also
// while the previous frame is still finished and the next one arrives (see "settings
// per frame" below; fmt_localmax and fmt_blob keep them per frame buffer).  At most two
// frames are in flight (each stage finishes a frame before the next-but-one arrives,
// else its overrun flag), so four table entries, by frame number mod 4, never meet.
// delay_i and report_period_i act on the event port as events pass (events keep their
// order, a frame is admitted or skipped whole); a calibration write that comes during
// a frame's rows waits for its hm_eof (fmt_flatten: a frame is flattened with one
// calibration; cal_late_o if its queue overflows).
//
// Latency, processing-clock cycles from the frame's last heat-map row beat (hm_eof on
// the next cycle) to its last event on ev_*, dial 0, consumer ready: flatten 5,
// localmax <= 15 + n + m + e (n candidates, m maxima in the rows next to the last one,
// e <= 6 of them with a partial mask only; 12 + n without them), interp 24, tracker m + l + n + 7 after tp_eof for m moves, l
// lifts, n news without stale picks (see fmt_tracker's header; stale picks only when
// touches compete for a slot), event port 5 -- measured by tb/fmt_touch (see its
// docstring and the README for the numbers).
`default_nettype none
`include "fmt_defaults.vh"

module fmt_touch #(
    parameter ROWS        = `FMT_ROWS,          // heat-map rows
    parameter COLS        = `FMT_COLS,          // heat-map columns
    parameter HM_W        = `FMT_HM_W,          // cell width, unsigned
    parameter MAX_TOUCHES = `FMT_MAX_TOUCHES,   // contact limit (candidates, slots)
    parameter FRAME_W     = 16,                 // frame number width
    parameter ID_W        = 8,                  // contact ID width
    parameter TIME_W      = 32,                 // event time stamp width
    parameter EV_DEPTH    = 2048,               // event FIFO entries (power of two)
    parameter VF          = 12,                 // tracker: extra fraction bits of p, v
    parameter V_W         = 22,                 // tracker: velocity width
    parameter HOLD_W      = 12,                 // tracker: hold-off width
    parameter CNT_W       = 16,                 // monitor counter width
    parameter BLOBS       = 1,                  // 1: build the blob detector (blob_en_i
                                                // selects it at run time); 0: leave it out
                                                // (blob_en_i ignored, blob_flag_o = 0)
    parameter ROW_IDX_W   = (ROWS > 1) ? $clog2(ROWS) : 1,   // row index width
    parameter COL_IDX_W   = (COLS > 1) ? $clog2(COLS) : 1,   // column index width
    parameter LIM_W       = $clog2(MAX_TOUCHES + 1),         // contact limit width
    parameter CAL_W       = (HM_W > 16) ? HM_W : 16          // calibration data width
) (
    input  wire                  clk,
    input  wire                  rst,                // synchronous, active high
    // settings
    input  wire [HM_W-1:0]       threshold_i,        // coarse-touch threshold (flattened counts)
    input  wire                  moore_i,            // 1 Moore, 0 Von Neumann (maxima and fit)
    input  wire [LIM_W-1:0]      limit_i,            // contact limit (<= MAX_TOUCHES)
    input  wire                  bias_en_i,          // sub-cell bias correction on
    input  wire [15:0]           max_jump_i,         // tracker L1 gate (Q8.8)
    input  wire [15:0]           gate_step_i,        // tracker L1 gate growth per frame missed (Q8.8)
    input  wire [HOLD_W-1:0]     hold_off_i,         // frames missing before lift
    input  wire [3:0]            vel_shift_i,        // velocity filter gain 2^-S
    input  wire [V_W-2:0]        max_speed_i,        // velocity clamp
    input  wire [HM_W-1:0]       on_thr_i,           // activation threshold of a new contact
    input  wire [2:0]            confirm_i,          // frames a new contact is seen before its event
    input  wire [TIME_W-1:0]     delay_i,            // dial-a-latency (cycles)
    input  wire [TIME_W-1:0]     report_period_i,    // min cycles between reported frames
    input  wire                  blob_en_i,          // 1: blob detection, finger removal, blob events
    input  wire [HM_W-1:0]       blob_threshold_i,   // blob cell when z >= this (must be >= 1)
    input  wire [15:0]           blob_min_cells_i,   // a region of >= this many cells is a blob
    // calibration write port (fmt_flatten)
    input  wire                  cal_we_i,           // write one cell's offset or gain
    input  wire                  cal_sel_i,          // 0 offset, 1 gain (Q2.14)
    input  wire [ROW_IDX_W-1:0]  cal_row_i,          // cell row
    input  wire [COL_IDX_W-1:0]  cal_col_i,          // cell column
    input  wire [CAL_W-1:0]      cal_data_i,         // value (offset: low HM_W bits, gain: Q2.14)
    input  wire                  cal_re_i,           // read back cal_row_i/cal_col_i/cal_sel_i
    output wire                  cal_rvalid_o,       // read-back data valid (one cycle)
    output wire [CAL_W-1:0]      cal_rdata_o,        // read-back value
    input  wire                  sat_clr_i,          // clear the flattening saturation monitor
    // heat-map stream in
    input  wire                  hm_valid_i,         // one row this cycle
    input  wire [ROW_IDX_W-1:0]  hm_row_i,           // row index
    input  wire [FRAME_W-1:0]    hm_frame_i,         // frame number
    input  wire [COLS*HM_W-1:0]  hm_data_i,          // column c at [c*HM_W +: HM_W]
    input  wire                  hm_eof_i,           // end of frame
    // event stream out
    output wire                  ev_valid_o,         // an event is offered
    input  wire                  ev_ready_i,         // the consumer takes it
    output wire [FRAME_W-1:0]    ev_frame_o,         // frame number
    output wire [TIME_W-1:0]     ev_time_o,          // time stamp (cycles since reset)
    output wire [ID_W-1:0]       ev_id_o,            // contact ID
    output wire [1:0]            ev_type_o,          // 0 new, 1 move, 2 lift, 3 blob
    output wire [15:0]           ev_x_o,             // Q8.8 column coordinate
    output wire [15:0]           ev_y_o,             // Q8.8 row coordinate
    output wire [HM_W-1:0]       ev_strength_o,      // peak (flattened) cell
    output wire [15:0]           ev_axis_major_o,    // Q8.8
    output wire [15:0]           ev_axis_minor_o,    // Q8.8
    output wire [7:0]            ev_angle_o,         // pi/256
    output wire [7:0]            ev_flags_o,         // fit flags
    output wire                  ev_last_o,          // last event of the frame
    // monitor
    output wire [TIME_W-1:0]     now_o,              // time-stamp counter
    output wire                  sat_flag_o,         // flattening saturated (sticky)
    output wire                  cal_late_o,         // a calibration write went into a frame (sticky)
    output wire [CNT_W-1:0]      sat_count_o,        // saturated cells
    output wire                  lm_overflow_o,      // a frame had more maxima than the limit (sticky)
    output wire [CNT_W-1:0]      lm_drop_count_o,    // candidates dropped by the limit
    output wire                  lm_overrun_o,       // localmax overrun (sticky)
    output wire                  trk_drop_o,         // tracker: touches beyond MAX_TOUCHES (sticky)
    output wire                  trk_noslot_o,       // tracker: new touch without a free slot (sticky)
    output wire                  trk_overrun_o,      // tracker: touches while busy (sticky)
    output wire [CNT_W-1:0]      ev_drop_count_o,    // event port: frames dropped (no room)
    output wire [CNT_W-1:0]      ev_skip_count_o,    // event port: frames skipped (report rate)
    output wire                  ev_overflow_o,      // event port: a frame was dropped (sticky)
    output wire                  blob_flag_o         // blobs: > MAX_BLOBS in a frame or overrun (sticky)
);

    // ---- settings per frame ---------------------------------------------------------
    // Every frame is processed with the settings present in the cycle its first row
    // beat enters (hm_valid_i after the previous hm_eof_i), whatever changes while it
    // travels: the values are written into a table indexed by the frame number mod 4
    // (at most two frames are in flight: see the header), and each stage reads the
    // entry of the frame it works on.
    //   intake (fmt_localmax and fmt_blob, which keep them per frame buffer): the
    //     threshold, moore, limit, blob threshold and min-cells, in registers loaded in
    //     the cycle before the frame's first flattened row (the first-row marker moves
    //     along fmt_flatten's FLAT_LAT cycles), constant over its flattened rows;
    //   fits and blob glue: moore, bias and blob_en by the frame number of the
    //     candidate, blob-list and blob-mask streams; the fine touches' blob_en is the
    //     candidates' delayed by fmt_interp's latency, the events' is registered at the
    //     tracker frame's first beat (no table read in front of the tracker);
    //   tracker: its seven settings in a register, loaded after the frame's cand_eof
    //     once the tracker is idle (before the frame's first touch reaches it).
    localparam FLAT_LAT = 5;                           // fmt_flatten's fixed latency
    localparam TRK_W    = HM_W + 3 + 16 + 16 + HOLD_W + 4 + (V_W - 1);   // tracker settings
    localparam IN_W     = HM_W + 1 + LIM_W + HM_W + 16;       // intake settings
    reg                    in_q;                       // a frame is arriving (row .. eof)
    wire                   first_row = hm_valid_i && !in_q;
    wire [1:0]             fi = hm_frame_i[1:0];       // table index of the arriving frame
    (* ram_style = "distributed" *)
    reg  [IN_W-1:0]        sti_mem [0:3];              // intake settings per frame mod 4
    (* ram_style = "distributed" *)
    reg  [TRK_W-1:0]       stt_mem [0:3];              // tracker settings per frame mod 4
    reg  [3:0]             moo_v, bia_v, ben_v;        // moore, bias, blob_en per frame mod 4
    reg  [FLAT_LAT-2:0]    fp_q;                       // the first-row marker, delayed
    reg  [2*FLAT_LAT-3:0]  fpi_q;                      // its table index, delayed
    reg  [IN_W-1:0]        in_set_q;                   // intake settings of the frame
    wire [1:0]             fpi_l = fpi_q[2*FLAT_LAT-3 -: 2];

    always @(posedge clk) begin
        if (first_row) begin
            sti_mem[fi] <= {threshold_i, moore_i, limit_i, blob_threshold_i, blob_min_cells_i};
            stt_mem[fi] <= {on_thr_i, confirm_i, max_jump_i, gate_step_i, hold_off_i, vel_shift_i,
                            max_speed_i};
        end
    end

    always @(posedge clk) begin
        if (rst) begin
            in_q     <= 1'b0;
            moo_v    <= 4'd0;
            bia_v    <= 4'd0;
            ben_v    <= 4'd0;
            fp_q     <= {(FLAT_LAT-1){1'b0}};
            fpi_q    <= {(2*FLAT_LAT-2){1'b0}};
            in_set_q <= {IN_W{1'b0}};
        end else begin
            if (hm_eof_i)        in_q <= 1'b0;
            else if (hm_valid_i) in_q <= 1'b1;
            if (first_row) begin
                moo_v[fi] <= moore_i;
                bia_v[fi] <= bias_en_i;
                ben_v[fi] <= (BLOBS != 0) && blob_en_i;
            end
            fp_q  <= {fp_q[FLAT_LAT-3:0], first_row};
            fpi_q <= {fpi_q[2*FLAT_LAT-5:0], fi};
            if (fp_q[FLAT_LAT-2])             // the frame's first flattened row is next
                in_set_q <= sti_mem[fpi_l];
        end
    end
    wire [HM_W-1:0]        thr_f   = in_set_q[IN_W-1 -: HM_W];
    wire                   moore_f = in_set_q[IN_W-HM_W-1];
    wire [LIM_W-1:0]       limit_f = in_set_q[HM_W+16+LIM_W-1 -: LIM_W];
    wire [HM_W-1:0]        bthr_f  = in_set_q[16+HM_W-1 -: HM_W];
    wire [15:0]            minc_f  = in_set_q[15:0];

    // ---- flatten ------------------------------------------------------------------
    wire                   f_valid, f_eof;
    wire [ROW_IDX_W-1:0]   f_row;
    wire [FRAME_W-1:0]     f_frame;
    wire [COLS*HM_W-1:0]   f_data;
    /* verilator lint_off UNUSEDSIGNAL */   // per-column saturation bits: only the sticky flag is used
    wire [COLS-1:0]        f_sat;
    /* verilator lint_on UNUSEDSIGNAL */

    fmt_flatten #(.ROWS(ROWS), .COLS(COLS), .HM_W(HM_W), .FRAME_W(FRAME_W), .CNT_W(CNT_W),
                  .CAL_W(CAL_W)) u_flatten (
        .clk(clk), .rst(rst),
        .hm_valid_i(hm_valid_i), .hm_row_i(hm_row_i), .hm_frame_i(hm_frame_i),
        .hm_data_i(hm_data_i), .hm_eof_i(hm_eof_i),
        .hm_valid_o(f_valid), .hm_row_o(f_row), .hm_frame_o(f_frame), .hm_data_o(f_data),
        .hm_sat_o(f_sat), .hm_eof_o(f_eof),
        .cal_we_i(cal_we_i), .cal_sel_i(cal_sel_i), .cal_row_i(cal_row_i),
        .cal_col_i(cal_col_i), .cal_data_i(cal_data_i),
        .cal_re_i(cal_re_i), .cal_rvalid_o(cal_rvalid_o), .cal_rdata_o(cal_rdata_o),
        .cal_late_o(cal_late_o),
        .sat_clr_i(sat_clr_i), .sat_flag_o(sat_flag_o), .sat_count_o(sat_count_o));

    // ---- local maxima -------------------------------------------------------------
    localparam FOUND_W = $clog2(ROWS * COLS + 1);
    wire                   c_valid, c_eof;
    wire [FRAME_W-1:0]     c_frame;
    wire [ROW_IDX_W-1:0]   c_row;
    wire [COL_IDX_W-1:0]   c_col;
    wire [9*HM_W-1:0]      c_z;
    wire [8:0]             c_missing;
    wire [LIM_W-1:0]       c_count;
    /* verilator lint_off UNUSEDSIGNAL */   // per-frame counts: monitor only, not needed here
    wire [FOUND_W-1:0]     c_found;
    wire                   c_incomplete;
    /* verilator lint_on UNUSEDSIGNAL */
    wire                   c_overflow;

    fmt_localmax #(.ROWS(ROWS), .COLS(COLS), .HM_W(HM_W), .MAX_TOUCHES(MAX_TOUCHES),
                   .FRAME_W(FRAME_W), .CNT_W(CNT_W)) u_localmax (
        .clk(clk), .rst(rst),
        .threshold_i(thr_f), .moore_i(moore_f), .limit_i(limit_f),
        .hm_valid_i(f_valid), .hm_row_i(f_row), .hm_frame_i(f_frame), .hm_data_i(f_data),
        .hm_eof_i(f_eof),
        .cand_valid_o(c_valid), .cand_frame_o(c_frame), .cand_row_o(c_row),
        .cand_col_o(c_col), .cand_z_o(c_z), .cand_missing_o(c_missing),
        .cand_eof_o(c_eof), .cand_count_o(c_count), .cand_found_o(c_found),
        .cand_overflow_o(c_overflow), .cand_incomplete_o(c_incomplete),
        .overflow_flag_o(lm_overflow_o), .drop_count_o(lm_drop_count_o),
        .overrun_o(lm_overrun_o));

    // ---- fits -----------------------------------------------------------------------
    wire                   t_valid, t_eof;
    wire [FRAME_W-1:0]     t_frame;
    wire [15:0]            t_x, t_y, t_major, t_minor;
    wire [HM_W-1:0]        t_strength;
    wire [7:0]             t_angle, t_flags;
    /* verilator lint_off UNUSEDSIGNAL */   // pass-through monitor fields
    wire [LIM_W-1:0]       t_count;
    wire                   t_overflow;
    /* verilator lint_on UNUSEDSIGNAL */

    fmt_interp #(.ROWS(ROWS), .COLS(COLS), .HM_W(HM_W), .FRAME_W(FRAME_W), .CNT_W(LIM_W)) u_interp (
        .clk(clk), .rst(rst),
        .moore_i(moo_v[c_frame[1:0]]), .bias_en_i(bia_v[c_frame[1:0]]),
        .cand_valid_i(c_valid), .cand_frame_i(c_frame), .cand_row_i(c_row), .cand_col_i(c_col),
        .cand_z_i(c_z), .cand_missing_i(c_missing), .cand_eof_i(c_eof), .cand_count_i(c_count),
        .cand_overflow_i(c_overflow),
        .tp_valid_o(t_valid), .tp_frame_o(t_frame), .tp_x_o(t_x), .tp_y_o(t_y),
        .tp_strength_o(t_strength), .tp_axis_major_o(t_major), .tp_axis_minor_o(t_minor),
        .tp_angle_o(t_angle), .tp_flags_o(t_flags), .tp_eof_o(t_eof), .tp_count_o(t_count),
        .tp_overflow_o(t_overflow));

    // ---- blobs (beside the local maxima) ------------------------------------------
    localparam MAX_BLOBS = 8;                          // blob records per frame
    localparam BAREA_W   = $clog2(ROWS * COLS + 1);
    localparam BCNT_W    = $clog2(MAX_BLOBS + 1);
    localparam TI_W      = $clog2(MAX_TOUCHES + 1);    // touch index / count width
    localparam TPD_W     = FRAME_W + 4 * 16 + HM_W + 16; // held touch beat
    localparam BRD_W     = 32 + HM_W;                  // held blob record (cx, cy, peak)

    wire                   b_valid, b_eof, m_ready;
    wire [FRAME_W-1:0]     b_frame;
    wire [15:0]            b_cx, b_cy;
    wire [HM_W-1:0]        b_peak;
    wire                   m_data;
    /* verilator lint_off UNUSEDSIGNAL */   // blob fields and monitors not used by the events
    wire [FRAME_W-1:0]     m_frame;
    wire [BAREA_W-1:0]     b_area, b_found;
    wire [ROW_IDX_W-1:0]   b_rmin, b_rmax, b_prow;
    wire [COL_IDX_W-1:0]   b_cmin, b_cmax, b_pcol;
    wire [BCNT_W-1:0]      b_count;
    wire                   b_ovf, b_inc, b_ovf_flag, b_overrun;
    /* verilator lint_on UNUSEDSIGNAL */
    wire [ROW_IDX_W-1:0]   m_q_row;
    wire [COL_IDX_W-1:0]   m_q_col;

    generate
        if (BLOBS != 0) begin : g_blob
        fmt_blob #(.ROWS(ROWS), .COLS(COLS), .HM_W(HM_W), .MAX_BLOBS(MAX_BLOBS),
                   .FRAME_W(FRAME_W), .ROW_IDX_W(ROW_IDX_W), .COL_IDX_W(COL_IDX_W),
                   .MINC_W(16)) u_blob (
            .clk(clk), .rst(rst),
            .blob_threshold_i(bthr_f), .blob_min_cells_i(minc_f),
            .hm_valid_i(f_valid), .hm_row_i(f_row), .hm_frame_i(f_frame), .hm_data_i(f_data),
            .hm_eof_i(f_eof),
            .blob_valid_o(b_valid), .blob_frame_o(b_frame), .blob_area_o(b_area),
            .blob_cx_o(b_cx), .blob_cy_o(b_cy), .blob_rmin_o(b_rmin), .blob_cmin_o(b_cmin),
            .blob_rmax_o(b_rmax), .blob_cmax_o(b_cmax), .blob_peak_o(b_peak),
            .blob_peak_row_o(b_prow), .blob_peak_col_o(b_pcol), .blob_eof_o(b_eof),
            .blob_count_o(b_count), .blob_found_o(b_found), .blob_overflow_o(b_ovf),
            .blob_incomplete_o(b_inc),
            .mask_ready_o(m_ready), .mask_frame_o(m_frame), .mask_q_row_i(m_q_row),
            .mask_q_col_i(m_q_col), .mask_q_data_o(m_data),
            .overflow_flag_o(b_ovf_flag), .overrun_o(b_overrun));
        end else begin : g_no_blob
            // the settings and the mask query have no reader without the detector
            wire unused_blob = &{1'b0, bthr_f, minc_f, m_q_row, m_q_col};
            assign {b_valid, b_eof, m_ready, m_data, b_ovf_flag, b_overrun} = 6'd0;
            assign {b_frame, b_cx, b_cy, b_peak, m_frame, b_area, b_found, b_rmin, b_rmax,
                    b_prow, b_cmin, b_cmax, b_pcol, b_count, b_ovf, b_inc} = 0;
        end
    endgenerate
    assign blob_flag_o = b_ovf_flag | b_overrun;
    // the blob path is in use for the frame of each stream (blob_en of that frame)
    localparam INTERP_LAT = 24;                        // fmt_interp: candidate -> touch, fixed
    wire bon_c = ben_v[c_frame[1:0]];                  // candidates
    wire bon_t;                                        // fine touches: bon_c INTERP_LAT cycles
    fmt_interp_dly #(.W(1), .N(INTERP_LAT), .RST(1)) u_bon_t (   // old, from a flip-flop (no
        .clk(clk), .rst(rst), .d_i(bon_c), .q_o(bon_t));         // table read before the tracker)
    wire bon_m = ben_v[m_frame[1:0]];                  // the blob mask
    wire bon_b = ben_v[b_frame[1:0]];                  // the blob list
    // synthesis translate_off
    reg [INTERP_LAT-1:0] chk_v_q;                      // fmt_interp's latency is INTERP_LAT
    always @(posedge clk) begin
        chk_v_q <= rst ? {INTERP_LAT{1'b0}} : {chk_v_q[INTERP_LAT-2:0], c_valid | c_eof};
        if (!rst && (chk_v_q[INTERP_LAT-1] != (t_valid | t_eof))) begin
            $display("fmt_touch: fmt_interp's latency is not INTERP_LAT = %0d", INTERP_LAT);
            $finish;
        end
    end
    // synthesis translate_on

    // ---- finger removal: hold the touch beats until the mask is written --------------
    reg  [ROW_IDX_W-1:0]   cr_mem [0:(1<<TI_W)-1];   // candidate cell per touch index
    reg  [COL_IDX_W-1:0]   cc_mem [0:(1<<TI_W)-1];
    reg  [TPD_W-1:0]       tp_mem [0:(1<<TI_W)-1];   // touch beats of the frame
    reg  [TI_W-1:0]        ci_q, ti_q, tn_q, rj_q, s0_idx_q, s1_idx_q;
    reg                    have_tp_q, have_mask_q, have_blob_q, rp_q;
    reg                    s0_valid_q, s0_eof_q, s1_valid_q, s1_eof_q;

    always @(posedge clk) begin
        if (c_valid && bon_c && ci_q < MAX_TOUCHES) begin
            cr_mem[ci_q] <= c_row;
            cc_mem[ci_q] <= c_col;
        end
        if (t_valid && bon_t && ti_q < MAX_TOUCHES)
            tp_mem[ti_q] <= {t_frame, t_x, t_y, t_major, t_minor, t_strength,
                                       t_angle, t_flags};
    end

    always @(posedge clk) begin
        if (rst) begin
            ci_q <= {TI_W{1'b0}};
            ti_q <= {TI_W{1'b0}};
            tn_q <= {TI_W{1'b0}};
            rj_q <= {TI_W{1'b0}};
            s0_idx_q <= {TI_W{1'b0}};
            s1_idx_q <= {TI_W{1'b0}};
            have_tp_q <= 1'b0;
            have_mask_q <= 1'b0;
            have_blob_q <= 1'b0;
            rp_q <= 1'b0;
            s0_valid_q <= 1'b0;
            s0_eof_q <= 1'b0;
            s1_valid_q <= 1'b0;
            s1_eof_q <= 1'b0;
        end else begin
            s0_valid_q <= 1'b0;
            s0_eof_q   <= 1'b0;
            s1_valid_q <= s0_valid_q;             // the query's answer comes now
            s1_eof_q   <= s0_eof_q;
            s1_idx_q   <= s0_idx_q;
            if (c_valid && bon_c && ci_q < MAX_TOUCHES) ci_q <= ci_q + 1'b1;
            if (c_eof) ci_q <= {TI_W{1'b0}};
            if (t_valid && bon_t && ti_q < MAX_TOUCHES) ti_q <= ti_q + 1'b1;
            if (t_eof && bon_t) begin
                tn_q      <= ti_q + {{(TI_W-1){1'b0}}, t_valid};
                ti_q      <= {TI_W{1'b0}};
                have_tp_q <= 1'b1;
            end else if (t_eof) begin
                ti_q <= {TI_W{1'b0}};
            end
            if (m_ready && bon_m) have_mask_q <= 1'b1;
            if (b_eof && bon_b) have_blob_q <= 1'b1;
            if (!rp_q && have_tp_q && have_mask_q && have_blob_q) begin
                rp_q        <= 1'b1;                  // replay the frame's touches
                rj_q        <= {TI_W{1'b0}};
                have_tp_q   <= 1'b0;
                have_mask_q <= 1'b0;
                have_blob_q <= 1'b0;
            end
            if (rp_q) begin
                if (rj_q < tn_q) begin
                    s0_valid_q <= 1'b1;               // the cell is queried this cycle
                    s0_idx_q   <= rj_q;
                    rj_q       <= rj_q + 1'b1;
                end else begin
                    s0_eof_q <= 1'b1;
                    rp_q     <= 1'b0;
                end
            end
        end
    end

    assign m_q_row = cr_mem[rj_q];
    assign m_q_col = cc_mem[rj_q];
    wire [TPD_W-1:0]     s1_beat = tp_mem[s1_idx_q];
    wire                 s1_keep = s1_valid_q && !m_data;

    // tracker input: the chain (a frame with blobs off) or the replayed touches (blobs
    // on; the replay of a frame ends long before the next frame's touches)
    wire                   rsel    = s1_valid_q || s1_eof_q;    // a replay beat
    wire                   g_valid = s1_keep  || (t_valid && !bon_t);
    wire                   g_eof   = s1_eof_q || (t_eof && !bon_t);
    wire [FRAME_W-1:0]     g_frame;
    wire [15:0]            g_x, g_y, g_major, g_minor;
    wire [HM_W-1:0]        g_strength;
    wire [7:0]             g_angle, g_flags;
    assign {g_frame, g_x, g_y, g_major, g_minor, g_strength, g_angle, g_flags} =
        rsel ? (s1_eof_q ? {t_frame, {(TPD_W-FRAME_W){1'b0}}} : s1_beat)
             : {t_frame, t_x, t_y, t_major, t_minor, t_strength, t_angle, t_flags};

    // ---- frame matching -------------------------------------------------------------
    wire                   k_valid, k_last;
    wire [FRAME_W-1:0]     k_frame;
    wire [ID_W-1:0]        k_id;
    wire [1:0]             k_type;
    wire [15:0]            k_x, k_y, k_major, k_minor;
    wire [HM_W-1:0]        k_strength;
    wire [7:0]             k_angle, k_flags;
    wire                   k_busy;

    // the tracker's settings: the entry of the frame whose candidates ended last, loaded
    // once the tracker is idle and not taking a frame's touches
    reg  [TRK_W-1:0]       trk_set_q;
    reg  [1:0]             tsi_q;                      // table index of that frame
    reg                    tsp_q;                      // a load is pending
    reg                    tin_q;                      // the tracker takes a frame's touches
    reg                    bk_q;                       // blob_en of the tracker's frame
    always @(posedge clk) begin
        if (rst) begin
            trk_set_q <= {TRK_W{1'b0}};
            tsi_q     <= 2'd0;
            tsp_q     <= 1'b0;
            tin_q     <= 1'b0;
            bk_q      <= 1'b0;
        end else begin
            if (c_eof) begin
                tsi_q <= c_frame[1:0];
                tsp_q <= 1'b1;
            end else if (tsp_q && !k_busy && !tin_q) begin
                trk_set_q <= stt_mem[tsi_q];
                tsp_q     <= 1'b0;
            end
            if (g_eof)        tin_q <= 1'b0;
            else if (g_valid) tin_q <= 1'b1;
            // blob_en of the frame the tracker works on (for its events' ev_last)
            if ((g_valid || g_eof) && !tin_q) bk_q <= ben_v[g_frame[1:0]];
        end
    end
    wire [HM_W-1:0]        on_thr_f    = trk_set_q[TRK_W-1 -: HM_W];
    wire [2:0]             confirm_f   = trk_set_q[TRK_W-HM_W-1 -: 3];
    wire [15:0]            max_jump_f  = trk_set_q[TRK_W-HM_W-4 -: 16];
    wire [15:0]            gate_step_f = trk_set_q[TRK_W-HM_W-20 -: 16];
    wire [HOLD_W-1:0]      hold_off_f  = trk_set_q[4+V_W-1 +: HOLD_W];
    wire [3:0]             vel_shift_f = trk_set_q[V_W-1 +: 4];
    wire [V_W-2:0]         max_speed_f = trk_set_q[V_W-2:0];

    fmt_tracker #(.MAX_TOUCHES(MAX_TOUCHES), .HM_W(HM_W), .FRAME_W(FRAME_W), .ID_W(ID_W),
                  .VF(VF), .V_W(V_W), .HOLD_W(HOLD_W)) u_tracker (
        .clk(clk), .rst(rst),
        .max_jump_i(max_jump_f), .gate_step_i(gate_step_f), .hold_off_i(hold_off_f),
        .vel_shift_i(vel_shift_f), .max_speed_i(max_speed_f), .on_thr_i(on_thr_f),
        .confirm_i(confirm_f),
        .tp_valid_i(g_valid), .tp_frame_i(g_frame), .tp_x_i(g_x), .tp_y_i(g_y),
        .tp_strength_i(g_strength), .tp_axis_major_i(g_major), .tp_axis_minor_i(g_minor),
        .tp_angle_i(g_angle), .tp_flags_i(g_flags), .tp_eof_i(g_eof),
        .ev_valid_o(k_valid), .ev_frame_o(k_frame), .ev_id_o(k_id), .ev_type_o(k_type),
        .ev_x_o(k_x), .ev_y_o(k_y), .ev_strength_o(k_strength), .ev_axis_major_o(k_major),
        .ev_axis_minor_o(k_minor), .ev_angle_o(k_angle), .ev_flags_o(k_flags),
        .ev_last_o(k_last),
        .drop_flag_o(trk_drop_o), .noslot_flag_o(trk_noslot_o),
        .overrun_flag_o(trk_overrun_o), .busy_o(k_busy));

    // ---- blob events after the tracker's events of the frame -------------------------
    reg  [BRD_W-1:0]       br_mem [0:(1<<BCNT_W)-1];    // cx, cy, peak
    reg  [BCNT_W-1:0]      bc_q, bn_q, bi_q;
    reg  [FRAME_W-1:0]     bf_q;
    reg                    wt_q, em_q;

    always @(posedge clk) begin
        if (b_valid && bon_b && bc_q < MAX_BLOBS)
            br_mem[bc_q] <= {b_cx, b_cy, b_peak};
    end

    always @(posedge clk) begin
        if (rst) begin
            bc_q <= {BCNT_W{1'b0}};
            bn_q <= {BCNT_W{1'b0}};
            bi_q <= {BCNT_W{1'b0}};
            bf_q <= {FRAME_W{1'b0}};
            wt_q <= 1'b0;
            em_q <= 1'b0;
        end else begin
            if (b_valid && bon_b && bc_q < MAX_BLOBS) bc_q <= bc_q + 1'b1;
            if (b_eof) begin
                bc_q <= {BCNT_W{1'b0}};
                if (bon_b) begin
                    bn_q <= bc_q;
                    bf_q <= b_frame;
                end
            end
            if (s1_eof_q) wt_q <= 1'b1;       // tracker busy from the next cycle
            if (wt_q && !k_busy) begin                // its last event is out now
                wt_q <= 1'b0;
                em_q <= (bn_q != {BCNT_W{1'b0}});
                bi_q <= {BCNT_W{1'b0}};
            end
            if (em_q) begin
                bi_q <= bi_q + 1'b1;
                if (bi_q + 1'b1 == bn_q) em_q <= 1'b0;
            end
        end
    end

    wire [BRD_W-1:0] br_cur = br_mem[bi_q];
    // event port input: the tracker's events, then (blobs on) the frame's blob events
    wire               p_valid    = em_q ? 1'b1      : k_valid;
    wire [FRAME_W-1:0] p_frame    = em_q ? bf_q      : k_frame;
    wire [ID_W-1:0]    p_id       = em_q ? {ID_W{1'b1}} : k_id;
    wire [1:0]         p_type     = em_q ? 2'd3      : k_type;
    wire [15:0]        p_x        = em_q ? br_cur[BRD_W-1 -: 16] : k_x;
    wire [15:0]        p_y        = em_q ? br_cur[HM_W +: 16]    : k_y;
    wire [HM_W-1:0]    p_strength = em_q ? br_cur[HM_W-1:0]      : k_strength;
    wire [15:0]        p_major    = em_q ? 16'd0     : k_major;
    wire [15:0]        p_minor    = em_q ? 16'd0     : k_minor;
    wire [7:0]         p_angle    = em_q ? 8'd0      : k_angle;
    wire [7:0]         p_flags    = em_q ? 8'd0      : k_flags;
    wire               p_last     = em_q ? (bi_q + 1'b1 == bn_q)
                                  : (k_last && !(bk_q && bn_q != {BCNT_W{1'b0}}));

    // ---- event port -----------------------------------------------------------------
    fmt_event_port #(.HM_W(HM_W), .FRAME_W(FRAME_W), .ID_W(ID_W), .TIME_W(TIME_W),
                     .DEPTH(EV_DEPTH), .MAX_EV(2 * MAX_TOUCHES + MAX_BLOBS), .CNT_W(CNT_W)) u_port (
        .clk(clk), .rst(rst),
        .delay_i(delay_i), .report_period_i(report_period_i),
        .in_valid_i(p_valid), .in_frame_i(p_frame), .in_id_i(p_id), .in_type_i(p_type),
        .in_x_i(p_x), .in_y_i(p_y), .in_strength_i(p_strength),
        .in_axis_major_i(p_major), .in_axis_minor_i(p_minor), .in_angle_i(p_angle),
        .in_flags_i(p_flags), .in_last_i(p_last),
        .ev_valid_o(ev_valid_o), .ev_ready_i(ev_ready_i), .ev_frame_o(ev_frame_o),
        .ev_time_o(ev_time_o), .ev_id_o(ev_id_o), .ev_type_o(ev_type_o), .ev_x_o(ev_x_o),
        .ev_y_o(ev_y_o), .ev_strength_o(ev_strength_o), .ev_axis_major_o(ev_axis_major_o),
        .ev_axis_minor_o(ev_axis_minor_o), .ev_angle_o(ev_angle_o), .ev_flags_o(ev_flags_o),
        .ev_last_o(ev_last_o),
        .now_o(now_o), .drop_count_o(ev_drop_count_o), .skip_count_o(ev_skip_count_o),
        .overflow_o(ev_overflow_o));

endmodule

`default_nettype wire
