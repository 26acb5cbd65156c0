// fmt_ctrl_tb_top -- SIMULATION-ONLY test top (not part of rtl/): fmt_ctrl_port +
// the generated fmt_regfile + small dummy core memories, so that the UART, the frame
// protocol, the register bus, the windows and the block-read port are all exercised.
//
// Block space: words 0..63 are a RAM (a heat-map snapshot, e.g. 4 x 6 cells) that the
// test preloads through mem_we_i/mem_addr_i/mem_wdata_i; any other word address A reads
// {~A, A} (a pattern the test predicts).  Registered read, BLK_LAT = 1.
// Tone-plan windows: TONE_TW / TONE_AMP write and read 32-entry memories at TONE_SEL;
// calibration windows: CAL_OFFSET / CAL_GAIN 8 x 8 memories at (CAL_ROW, CAL_COL).
// Status inputs: FRAME_COUNT and STATUS set bits come from the test; CTRL_ERRORS and
// CTRL_LAST_ERR from the port; STATUS bit 4 is set by every port error.
// Other read-only registers read fixed patterns (see the localparams).
`default_nettype none
`include "fmt_defaults.vh"

module fmt_ctrl_tb_top #(
    parameter DIV          = 4,
    parameter TIMEOUT_BITS = 20,
    parameter PAYLOAD_MAX  = 64,
    parameter FIFO_AW      = 4,
    parameter REGMAP_ID    = 0,
    parameter ROWS         = `FMT_ROWS,
    parameter COLS         = `FMT_COLS,
    parameter LOG2_N       = `FMT_LOG2_N,
    parameter HM_W         = `FMT_HM_W,
    parameter BIN_LO       = `FMT_BIN_LO,
    parameter BIN_STEP     = `FMT_BIN_STEP
) (
    input  wire         clk,
    input  wire         rst,
    input  wire         rxd_i,
    output wire         txd_o,
    input  wire         mem_we_i,
    input  wire [5:0]   mem_addr_i,
    input  wire [31:0]  mem_wdata_i,
    input  wire [31:0]  frame_count_i,
    input  wire [7:0]   status_set_i,
    input  wire         evs_valid_i,
    input  wire [191:0] evs_data_i,
    output wire         evs_ready_o,
    output wire         stream_en_o,
    output wire         lat_clear_o
);
    // fixed values of the core's status inputs (the test knows them)
    localparam [15:0] EV_DROP = 16'd3, EV_SKIP = 16'd5, FLAT_SAT = 16'd7, LM_DROP = 16'd9;
    localparam [15:0] LF_LAST = 16'd101, LF_MIN = 16'd100, LF_MAX = 16'd140;
    localparam [15:0] LL_LAST = 16'd201, LL_MIN = 16'd200, LL_MAX = 16'd240;
    localparam [15:0] LT_LAST = 16'd301, LT_MIN = 16'd300, LT_MAX = 16'd340;
    localparam [31:0] LF_COUNT = 32'd4242, LL_COUNT = 32'd4243, LT_COUNT = 32'd7;

    wire        reg_we, reg_re, blk_req, err_pulse;
    wire [15:0] reg_addr, blk_addr, err_count;
    wire [31:0] reg_wdata, reg_rdata;
    reg  [31:0] blk_rdata;
    wire [7:0]  err_last;

    fmt_ctrl_port #(
        .DIV(DIV), .TIMEOUT_BITS(TIMEOUT_BITS), .PAYLOAD_MAX(PAYLOAD_MAX), .FIFO_AW(FIFO_AW),
        .BLK_LAT(1), .EV_BYTES(24), .REGMAP_ID(REGMAP_ID), .ROWS(ROWS), .COLS(COLS),
        .LOG2_N(LOG2_N), .HM_W(HM_W), .BIN_LO(BIN_LO), .BIN_STEP(BIN_STEP)
    ) u_port (
        .clk(clk), .rst(rst), .rxd_i(rxd_i), .txd_o(txd_o),
        .reg_we_o(reg_we), .reg_re_o(reg_re), .reg_addr_o(reg_addr), .reg_wdata_o(reg_wdata),
        .reg_rdata_i(reg_rdata), .blk_req_o(blk_req), .blk_addr_o(blk_addr),
        .blk_rdata_i(blk_rdata), .evs_valid_i(evs_valid_i), .evs_data_i(evs_data_i),
        .evs_ready_o(evs_ready_o), .stream_en_o(stream_en_o), .err_count_o(err_count),
        .err_last_o(err_last), .err_pulse_o(err_pulse));

    // block RAM (heat-map snapshot)
    reg [31:0] mem [0:63];
    always @(posedge clk) begin
        if (mem_we_i) mem[mem_addr_i] <= mem_wdata_i;
        if (blk_req) blk_rdata <= (blk_addr < 16'd64) ? mem[blk_addr[5:0]] : {~blk_addr, blk_addr};
    end

    // tone-plan window memories
    wire [4:0]  tone_sel;
    wire        tone_tw_we, tone_amp_we, tone_tw_re, tone_amp_re;
    wire [31:0] tone_tw_wdata;
    wire [8:0]  tone_amp_wdata;
    reg  [31:0] tone_tw_mem [0:31];
    reg  [8:0]  tone_amp_mem [0:31];
    always @(posedge clk) begin
        if (tone_tw_we)  tone_tw_mem[tone_sel]  <= tone_tw_wdata;
        if (tone_amp_we) tone_amp_mem[tone_sel] <= tone_amp_wdata;
    end

    // calibration window memories, 8 x 8 cells at {CAL_ROW[2:0], CAL_COL[2:0]}
    wire [4:0]  cal_row;
    wire [5:0]  cal_col;
    wire        cal_off_we, cal_gain_we, cal_off_re, cal_gain_re;
    wire [15:0] cal_off_wdata, cal_gain_wdata;
    reg  [15:0] cal_off_mem [0:63];
    reg  [15:0] cal_gain_mem [0:63];
    wire [5:0]  cal_idx = {cal_row[2:0], cal_col[2:0]};
    always @(posedge clk) begin
        if (cal_off_we)  cal_off_mem[cal_idx]  <= cal_off_wdata;
        if (cal_gain_we) cal_gain_mem[cal_idx] <= cal_gain_wdata;
    end

    /* verilator lint_off PINCONNECTEMPTY */  // unused rw outputs of the register file
    fmt_regfile u_regs (
        .clk(clk), .rst(rst), .reg_we_i(reg_we), .reg_re_i(reg_re), .reg_addr_i(reg_addr),
        .reg_wdata_i(reg_wdata), .reg_rdata_o(reg_rdata),
        .scratch_o(), .run_o(), .pn_enable_o(), .pn_chip_len_o(), .pn_rx_delay_o(),
        .windows_m_o(), .tone_sel_o(tone_sel),
        .tone_tw_we_o(tone_tw_we), .tone_tw_wdata_o(tone_tw_wdata), .tone_tw_re_o(tone_tw_re),
        .tone_tw_rdata_i(tone_tw_mem[tone_sel]),
        .tone_amp_we_o(tone_amp_we), .tone_amp_wdata_o(tone_amp_wdata), .tone_amp_re_o(tone_amp_re),
        .tone_amp_rdata_i(tone_amp_mem[tone_sel]),
        .touch_threshold_o(), .touch_mode_o(), .contact_limit_o(), .track_max_jump_o(),
        .track_gate_step_o(), .track_hold_off_o(), .track_vel_shift_o(), .track_max_speed_o(),
        .blob_threshold_o(), .blob_min_cells_o(), .touch_on_threshold_o(), .track_confirm_o(),
        .cal_row_o(cal_row), .cal_col_o(cal_col),
        .cal_offset_we_o(cal_off_we), .cal_offset_wdata_o(cal_off_wdata), .cal_offset_re_o(cal_off_re),
        .cal_offset_rdata_i(cal_off_mem[cal_idx]),
        .cal_gain_we_o(cal_gain_we), .cal_gain_wdata_o(cal_gain_wdata), .cal_gain_re_o(cal_gain_re),
        .cal_gain_rdata_i(cal_gain_mem[cal_idx]),
        .latency_dial_o(), .report_period_o(),
        .frame_count_i(frame_count_i),
        .status_set_i(status_set_i | {3'b000, err_pulse, 4'b0000}), .status_o(),
        .ctrl_errors_i(err_count), .ctrl_last_err_i(err_last),
        .ev_drop_count_i(EV_DROP), .ev_skip_count_i(EV_SKIP), .flat_sat_count_i(FLAT_SAT),
        .lm_drop_count_i(LM_DROP), .sat_clear_we_o(), .sat_clear_wdata_o(),
        .lat_first_last_i(LF_LAST), .lat_first_min_i(LF_MIN), .lat_first_max_i(LF_MAX),
        .lat_first_count_i(LF_COUNT),
        .lat_last_last_i(LL_LAST), .lat_last_min_i(LL_MIN), .lat_last_max_i(LL_MAX),
        .lat_last_count_i(LL_COUNT),
        .lat_trig_last_i(LT_LAST), .lat_trig_min_i(LT_MIN), .lat_trig_max_i(LT_MAX),
        .lat_trig_count_i(LT_COUNT), .lat_trig_armed_i(1'b1),
        .lat_clear_we_o(lat_clear_o), .lat_clear_wdata_o(),
        // snapshot control: this top's block RAM always holds a whole frame, so
        // SNAP_STATUS reads "complete" (bit 31) at once
        .snap_req_we_o(), .snap_req_wdata_o(), .snap_status_i(32'h8000_0000));
    /* verilator lint_on PINCONNECTEMPTY */

    wire unused_ok = &{1'b0, tone_tw_re, tone_amp_re, cal_off_re, cal_gain_re, cal_row[4:3], cal_col[5:3]};

endmodule
`default_nettype wire
