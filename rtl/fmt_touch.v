// fmt_touch -- the touch-processing top: heat-map stream in, touch-event stream out.
//
//   fmt_flatten -> fmt_localmax -> fmt_interp -> fmt_tracker -> fmt_event_port
//
// Twin: sim/fmt/touch.py process_frames(fixed=True, blobs=False): per frame the same
// events in the same order (time stamps excepted).  The run-time settings are input
// ports (the core's register file drives them); change them between frames.
//
// Latency, processing-clock cycles from the frame's last heat-map row beat (hm_eof on
// the next cycle) to its last event on ev_*, dial 0, consumer ready: flatten 4,
// localmax 6 + n (n candidates; more when many maxima sit in the last rows),
// interp 23, tracker events + 5 after tp_eof, event port 3 -- measured by
// tb/fmt_touch (see its docstring and the README for the numbers).
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
    input  wire [15:0]           hold_jump_i,        // tracker L1 gate in hold-off (Q8.8)
    input  wire [HOLD_W-1:0]     hold_off_i,         // frames missing before lift
    input  wire [3:0]            vel_shift_i,        // velocity filter gain 2^-S
    input  wire [V_W-2:0]        max_speed_i,        // velocity clamp
    input  wire [TIME_W-1:0]     delay_i,            // dial-a-latency (cycles)
    input  wire [TIME_W-1:0]     report_period_i,    // min cycles between reported frames
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
    output wire [1:0]            ev_type_o,          // 0 new, 1 move, 2 lift
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
    output wire [CNT_W-1:0]      sat_count_o,        // saturated cells
    output wire                  lm_overflow_o,      // a frame had more maxima than the limit (sticky)
    output wire [CNT_W-1:0]      lm_drop_count_o,    // candidates dropped by the limit
    output wire                  lm_overrun_o,       // localmax overrun (sticky)
    output wire                  trk_drop_o,         // tracker: touches beyond MAX_TOUCHES (sticky)
    output wire                  trk_noslot_o,       // tracker: new touch without a free slot (sticky)
    output wire                  trk_overrun_o,      // tracker: touches while busy (sticky)
    output wire [CNT_W-1:0]      ev_drop_count_o,    // event port: frames dropped (no room)
    output wire [CNT_W-1:0]      ev_skip_count_o,    // event port: frames skipped (report rate)
    output wire                  ev_overflow_o       // event port: a frame was dropped (sticky)
);

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
        .threshold_i(threshold_i), .moore_i(moore_i), .limit_i(limit_i),
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
        .moore_i(moore_i), .bias_en_i(bias_en_i),
        .cand_valid(c_valid), .cand_frame(c_frame), .cand_row(c_row), .cand_col(c_col),
        .cand_z(c_z), .cand_missing(c_missing), .cand_eof(c_eof), .cand_count(c_count),
        .cand_overflow(c_overflow),
        .tp_valid(t_valid), .tp_frame(t_frame), .tp_x(t_x), .tp_y(t_y),
        .tp_strength(t_strength), .tp_axis_major(t_major), .tp_axis_minor(t_minor),
        .tp_angle(t_angle), .tp_flags(t_flags), .tp_eof(t_eof), .tp_count(t_count),
        .tp_overflow(t_overflow));

    // ---- frame matching -------------------------------------------------------------
    wire                   k_valid, k_last;
    wire [FRAME_W-1:0]     k_frame;
    wire [ID_W-1:0]        k_id;
    wire [1:0]             k_type;
    wire [15:0]            k_x, k_y, k_major, k_minor;
    wire [HM_W-1:0]        k_strength;
    wire [7:0]             k_angle, k_flags;
    /* verilator lint_off UNUSEDSIGNAL */   // busy: status only
    wire                   k_busy;
    /* verilator lint_on UNUSEDSIGNAL */

    fmt_tracker #(.MAX_TOUCHES(MAX_TOUCHES), .HM_W(HM_W), .FRAME_W(FRAME_W), .ID_W(ID_W),
                  .VF(VF), .V_W(V_W), .HOLD_W(HOLD_W)) u_tracker (
        .clk(clk), .rst(rst),
        .max_jump_i(max_jump_i), .hold_jump_i(hold_jump_i), .hold_off_i(hold_off_i),
        .vel_shift_i(vel_shift_i), .max_speed_i(max_speed_i),
        .tp_valid_i(t_valid), .tp_frame_i(t_frame), .tp_x_i(t_x), .tp_y_i(t_y),
        .tp_strength_i(t_strength), .tp_axis_major_i(t_major), .tp_axis_minor_i(t_minor),
        .tp_angle_i(t_angle), .tp_flags_i(t_flags), .tp_eof_i(t_eof),
        .ev_valid_o(k_valid), .ev_frame_o(k_frame), .ev_id_o(k_id), .ev_type_o(k_type),
        .ev_x_o(k_x), .ev_y_o(k_y), .ev_strength_o(k_strength), .ev_axis_major_o(k_major),
        .ev_axis_minor_o(k_minor), .ev_angle_o(k_angle), .ev_flags_o(k_flags),
        .ev_last_o(k_last),
        .drop_flag_o(trk_drop_o), .noslot_flag_o(trk_noslot_o),
        .overrun_flag_o(trk_overrun_o), .busy_o(k_busy));

    // ---- event port -----------------------------------------------------------------
    fmt_event_port #(.HM_W(HM_W), .FRAME_W(FRAME_W), .ID_W(ID_W), .TIME_W(TIME_W),
                     .DEPTH(EV_DEPTH), .MAX_EV(2 * MAX_TOUCHES), .CNT_W(CNT_W)) u_port (
        .clk(clk), .rst(rst),
        .delay_i(delay_i), .report_period_i(report_period_i),
        .in_valid_i(k_valid), .in_frame_i(k_frame), .in_id_i(k_id), .in_type_i(k_type),
        .in_x_i(k_x), .in_y_i(k_y), .in_strength_i(k_strength),
        .in_axis_major_i(k_major), .in_axis_minor_i(k_minor), .in_angle_i(k_angle),
        .in_flags_i(k_flags), .in_last_i(k_last),
        .ev_valid_o(ev_valid_o), .ev_ready_i(ev_ready_i), .ev_frame_o(ev_frame_o),
        .ev_time_o(ev_time_o), .ev_id_o(ev_id_o), .ev_type_o(ev_type_o), .ev_x_o(ev_x_o),
        .ev_y_o(ev_y_o), .ev_strength_o(ev_strength_o), .ev_axis_major_o(ev_axis_major_o),
        .ev_axis_minor_o(ev_axis_minor_o), .ev_angle_o(ev_angle_o), .ev_flags_o(ev_flags_o),
        .ev_last_o(ev_last_o),
        .now_o(now_o), .drop_count_o(ev_drop_count_o), .skip_count_o(ev_skip_count_o),
        .overflow_o(ev_overflow_o));

endmodule

`default_nettype wire
