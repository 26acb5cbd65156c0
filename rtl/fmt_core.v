// fmt_core -- the whole FMT controller: transmit (fmt_tx), receive array
// (fmt_rx_array, heat-map stream), touch processing (fmt_touch, parallel event port),
// latency counters (fmt_latency), register file (fmt_regfile, generated) and the UART
// control port (fmt_ctrl_port) with a one-frame heat-map snapshot.
//
// Clocking (docs/ARCHITECTURE.md): one clock clk = CLK_PER_SAMPLE x fs.  The sample
// strobe ce_o is high on the first clk cycle after reset and every CLK_PER_SAMPLE
// cycles after it; the signal chain (DDS, receivers) advances on ce, the touch
// processing, latency counters and control port on every clk.  Sample k = k-th ce edge
// after reset: dac_o (registered in fmt_dds_bank) holds DDS sample k after ce edge k+2;
// adc_i is taken at every ce edge as the receivers' sample k (windows are samples
// k*N .. k*N+N-1).  fmt_pn_gen steps on ce too, with the chip length and receive delay
// in samples (the DDS sample k carries PN chip floor((k-1)/L), the receiver sample j the
// chip floor((j-1-d)/L), d = PN_RX_DELAY) -- tb/fmt_core checks it bit for bit against
// the models for C = 1 and 3.  The DDS bank shares one engine between C rows
// (ROWS_PER_ENGINE = C: ce is exactly every C clk cycles) and the receivers size their
// shared magnitude units for C clk per sample (fmt_rx_array CLK_PER_SAMPLE).
//
// Latency (fmt_latency): the frame end is the ce edge that takes the last ADC sample of
// a frame (M = WINDOWS_M windows, any 1 .. M_MAX: 0 is taken as 1, values above M_MAX
// as M_MAX (only possible when M_MAX < 255; docs/REGISTERS.md); latched at the last
// sample of each frame's first window and passed from there to the receivers, so both
// always agree on the frames); events count when they leave the parallel port
// (ev_valid_o & ev_ready_i).  trig_i is the external touch trigger.
//
// Registers (docs/REGISTERS.md) are written/read by the UART control port or by the
// local bus (bus_*; e.g. a board CPU or a testbench).  Both masters share the register
// file: in a cycle where the UART's master strobes, the local bus strobe is ignored
// (bus_*: one strobe at a time, read data on bus_rdata_o 1 cycle after bus_re_i).
// RUN = 0 forces dac_o to 0 (combinational, no extra latency).  TONE_TW / TONE_AMP
// ({enable, amplitude}) write the DDS bank through its settings port and read back a shadow copy (reset
// values = the DDS reset plan).  CAL_OFFSET / CAL_GAIN write fmt_touch's calibration
// memory and read a copy refreshed through its read-back port (see below).
// TOUCH_MODE bit 2 turns fmt_touch's blob detector on (blob_en_i; BLOB_THRESHOLD and
// BLOB_MIN_CELLS set it): fingers inside blobs are dropped and blobs leave as type-3 events.
// A build with BLOBS = 0 leaves the detector out (the bit then has no effect).
//
// Block-read space (BLKREAD): HEATMAP words 0 .. ROWS*COLS-1 = the snapshot (cell (r,c)
// at r*COLS + c, raw heat map before flattening); LAT_HIST words 0x8000 .. 0x801F = the
// latency histograms.  Read latency BLK_LAT = 3 (address -> row by a constant
// reciprocal multiply, row RAM read, column select).  A write of 1 to SNAP_REQ arms a
// capture; the next whole frame (from an hm_eof to the next) is written into the
// snapshot RAM (one row per heat-map beat) and SNAP_STATUS becomes {1, 0, 14'b0,
// frame}.  Other block addresses read 0.
//
// UART event stream: events leaving the parallel port (STREAM command on) go through
// fmt_report_fifo (2^STREAM_AW events) to the control port: a frame's events are sent
// all together, or not at all when the previous report is still waiting or the frame
// has more than 2^STREAM_AW events (STREAM_DROP_COUNT).  The UART is a monitor (REPORT_PERIOD decimates; 2.7 ms per event
// at 115200 baud).  Event payload: sim/fmt/protocol.py pack_event (24 bytes).
//
// Status: STATUS bits (w1c) are set by the blocks' sticky flags (bit 0 flattening
// saturation, 1 receiver FFT/cell overflow, 2 event-port drop, 3 latency saturation,
// 4 control-port error, 5 localmax overflow/overrun, 6 tracker drop/no slot/overrun,
// 7 blob overflow/overrun, 8 a calibration write went into a frame);
// status_o mirrors them for LEDs.  FRAME_COUNT counts heat-map frames (hm_eof).
`default_nettype none
`include "fmt_defaults.vh"
`include "fmt_regmap.vh"

module fmt_core #(
    parameter ROWS           = `FMT_ROWS,         // transmit rows
    parameter COLS           = `FMT_COLS,         // receive columns (even)
    parameter LOG2_N         = `FMT_LOG2_N,       // FFT size N = 2^LOG2_N
    parameter BIN_LO         = `FMT_BIN_LO,       // FFT bin of row 0
    parameter BIN_STEP       = `FMT_BIN_STEP,     // bins between rows
    parameter ADC_BITS       = `FMT_ADC_BITS,     // ADC word width (signed)
    parameter DAC_BITS       = `FMT_DAC_BITS,     // DAC word width per row (signed)
    parameter PHASE_BITS     = `FMT_PHASE_BITS,   // DDS phase accumulator width
    parameter SINE_BITS      = `FMT_SINE_BITS,    // DDS sine table width
    parameter AMP_BITS       = `FMT_AMP_BITS,     // DDS amplitude width
    parameter PN_BITS        = `FMT_PN_BITS,      // PN LFSR length
    parameter HM_W           = `FMT_HM_W,         // heat-map cell width
    parameter MAX_TOUCHES    = `FMT_MAX_TOUCHES,  // contact limit
    parameter CLK_PER_SAMPLE = 3,                 // clk cycles per ADC sample (1..4)
    parameter M_MAX          = 255,               // largest windows per frame M (1 .. 255)
    parameter EV_DEPTH       = 2048,              // event FIFO entries (power of two)
    parameter BLOBS          = 1,                 // 1: blob detector built (TOUCH_MODE bit 2
                                                  // turns it on); 0: left out, ~11k LUT6 less
    parameter UART_DIV       = 1085,              // clk cycles per UART bit (125 MHz: 115200 baud)
    parameter UART_TIMEOUT   = 40,                // control-port inter-byte timeout, bit times
    parameter STREAM_AW      = 5,                 // UART report FIFO: 2^STREAM_AW events (whole reports)
    parameter REGMAP_ID      = `FMT_REGMAP_ID,    // register-map id reported by INFO (generated)
    parameter ROW_W          = (ROWS > 1) ? $clog2(ROWS) : 1,   // row index width
    parameter COL_W          = (COLS > 1) ? $clog2(COLS) : 1    // column index width
) (
    input  wire                     clk,            // processing clock, CLK_PER_SAMPLE x fs
    input  wire                     rst,            // synchronous, active high
    output wire                     ce_o,           // sample strobe (DAC/ADC word timing)
    // analogue front end
    output wire [ROWS*DAC_BITS-1:0] dac_o,          // row r DAC word at [r*DAC_BITS +: DAC_BITS], signed
    input  wire [COLS*ADC_BITS-1:0] adc_i,          // column c ADC word at [c*ADC_BITS +: ADC_BITS], signed
    // low-latency parallel event port (docs/ARCHITECTURE.md touch-event stream)
    output wire                     ev_valid_o,     // an event is offered
    input  wire                     ev_ready_i,     // the consumer takes it
    output wire [15:0]              ev_frame_o,     // frame number
    output wire [31:0]              ev_time_o,      // clk time stamp when formed
    output wire [7:0]               ev_id_o,        // contact ID
    output wire [1:0]               ev_type_o,      // 0 new, 1 move, 2 lift
    output wire [15:0]              ev_x_o,         // column coordinate, Q8.8 cells
    output wire [15:0]              ev_y_o,         // row coordinate, Q8.8 cells
    output wire [HM_W-1:0]          ev_strength_o,  // peak flattened cell
    output wire [15:0]              ev_axis_major_o,// ellipse semi-axis, Q8.8 cells
    output wire [15:0]              ev_axis_minor_o,// ellipse semi-axis, Q8.8 cells
    output wire [7:0]               ev_angle_o,     // major-axis angle, pi/256
    output wire [7:0]               ev_flags_o,     // fit flags
    output wire                     ev_last_o,      // last event of the frame
    // external touch trigger (asynchronous; touch-to-data latency)
    input  wire                     trig_i,
    // UART control port
    input  wire                     uart_rx_i,      // receive line (asynchronous), idle high
    output wire                     uart_tx_o,      // transmit line, idle high
    // local register bus (second master of the register file)
    input  wire                     bus_we_i,       // write strobe
    input  wire                     bus_re_i,       // read strobe
    input  wire [15:0]              bus_addr_i,     // word address
    input  wire [31:0]              bus_wdata_i,    // write data
    output wire [31:0]              bus_rdata_o,    // read data, 1 cycle after bus_re_i
    // monitor
    output wire [10:0]              status_o,       // STATUS register (sticky flags)
    output wire [15:0]              frame_count_o   // heat-map frames since reset (wraps)
);
    localparam CPS    = CLK_PER_SAMPLE;
    localparam N      = 1 << LOG2_N;
    localparam MC_W   = $clog2(M_MAX + 1);        // width of M
    localparam LIM_W  = $clog2(MAX_TOUCHES + 1);
    localparam CELLS  = ROWS * COLS;
    localparam CPS_W  = (CPS > 1) ? $clog2(CPS) : 1;
    localparam CHIP_W = 10;                       // PN chip length in samples (PN_CHIP_LEN)
    localparam DLY_W  = 6;                        // PN receive delay in samples (PN_RX_DELAY)
    localparam [15:0] COLS16  = COLS[15:0];           // 16-bit copies for width-clean address arithmetic
    localparam [15:0] CELLS16 = CELLS[15:0];

    // ---------------------------------------------------------------- sample strobe
    reg  [CPS_W-1:0] ce_cnt_q;
    localparam [CPS_W-1:0] CPS_LAST = CPS[CPS_W-1:0] - 1'b1;
    wire             ce = (ce_cnt_q == {CPS_W{1'b0}});
    always @(posedge clk) begin
        if (rst || ce_cnt_q == CPS_LAST) ce_cnt_q <= {CPS_W{1'b0}};
        else                            ce_cnt_q <= ce_cnt_q + 1'b1;
    end
    assign ce_o = ce;

    // ---------------------------------------------------------------- register bus
    wire        u_we, u_re, blk_req, err_pulse, stream_en;
    wire [15:0] u_addr, blk_addr, err_count;
    wire [31:0] u_wdata, reg_rdata;
    wire [7:0]  err_last;
    wire        uart_bus = u_we | u_re;
    wire        reg_we    = uart_bus ? u_we    : bus_we_i;
    wire        reg_re    = uart_bus ? u_re    : bus_re_i;
    wire [15:0] reg_addr  = uart_bus ? u_addr  : bus_addr_i;
    wire [31:0] reg_wdata = uart_bus ? u_wdata : bus_wdata_i;
    assign bus_rdata_o = reg_rdata;

    // register file outputs
    wire [31:0] r_scratch, r_lat_dial, r_report_period;
    wire        r_run, r_pn_en;
    wire [9:0]  r_chip_len;
    wire [5:0]  r_rx_delay;
    wire [7:0]  r_windows_m;
    wire [10:0] r_status;
    wire [4:0]  r_tone_sel, r_limit, r_cal_row;
    wire [5:0]  r_cal_col;
    wire        tone_tw_we, tone_amp_we, tone_tw_re, tone_amp_re;
    wire [31:0] tone_tw_wdata;
    wire [8:0]  tone_amp_wdata;
    wire [15:0] r_threshold, r_max_jump, r_gate_step, r_blob_thr, r_on_thr;
    wire [2:0]  r_confirm;
    wire [2:0]  r_mode;
    wire [11:0] r_hold_off, r_blob_min;
    wire [3:0]  r_vel_shift;
    wire [20:0] r_max_speed;
    wire        cal_off_we, cal_gain_we, cal_off_re, cal_gain_re;
    wire [15:0] cal_off_wdata, cal_gain_wdata;
    wire        sat_clr_we, sat_clr_wd, lat_clr_we, lat_clr_wd, snap_we, snap_wd;

    // ---------------------------------------------------------------- transmit
    // tone-plan shadow (read-back of TONE_TW / TONE_AMP), reset = the DDS reset plan.
    // TONE_AMP = {enable, amplitude}: the amplitude goes to the DDS in the write cycle,
    // the enable in the next one (so two writes to the tone windows need one idle
    // cycle between them; the control port writes one word per 4 cycles).
    reg  [PHASE_BITS-1:0] tw_shadow_q  [0:ROWS-1];
    reg  [AMP_BITS:0]     amp_shadow_q [0:ROWS-1];
    reg                   en_pend_q, en_val_q;
    reg  [ROW_W-1:0]      en_row_q;
    wire                  tone_ok = ({27'd0, r_tone_sel} < ROWS);
    wire [ROW_W-1:0]      tone_row = r_tone_sel[ROW_W-1:0];
    integer i;
    always @(posedge clk) begin
        if (rst) begin
            for (i = 0; i < ROWS; i = i + 1) begin
                tw_shadow_q[i]  <= (BIN_LO + i * BIN_STEP) << (PHASE_BITS - LOG2_N);
                amp_shadow_q[i] <= {(AMP_BITS + 1){1'b1}};
            end
            en_pend_q <= 1'b0;
            en_val_q  <= 1'b1;
            en_row_q  <= {ROW_W{1'b0}};
        end else begin
            en_pend_q <= tone_amp_we && tone_ok;
            en_val_q  <= tone_amp_wdata[AMP_BITS];
            en_row_q  <= tone_row;
            if (tone_ok && tone_tw_we)  tw_shadow_q[tone_row]  <= tone_tw_wdata[PHASE_BITS-1:0];
            if (tone_ok && tone_amp_we) amp_shadow_q[tone_row] <= tone_amp_wdata[AMP_BITS:0];
        end
    end
    wire [31:0] tone_tw_rdata  = tone_ok ? {{(32 - PHASE_BITS){1'b0}}, tw_shadow_q[tone_row]} : 32'd0;
    wire [8:0]  tone_amp_rdata = tone_ok ? {{(8 - AMP_BITS){1'b0}}, amp_shadow_q[tone_row]} : 9'd0;
    wire                  dds_we   = en_pend_q | ((tone_tw_we | tone_amp_we) & tone_ok);
    wire [ROW_W-1:0]      dds_row  = en_pend_q ? en_row_q : tone_row;
    wire [1:0]            dds_sel  = en_pend_q ? 2'd2 : (tone_amp_we ? 2'd1 : 2'd0);
    wire [PHASE_BITS-1:0] dds_data = en_pend_q ? {{(PHASE_BITS - 1){1'b0}}, en_val_q} :
                                     tone_amp_we ? {{(PHASE_BITS - AMP_BITS){1'b0}}, tone_amp_wdata[AMP_BITS-1:0]} :
                                     tone_tw_wdata[PHASE_BITS-1:0];

    wire [ROWS*DAC_BITS-1:0] dac;
    wire                     rx_sign;
    /* verilator lint_off PINCONNECTEMPTY */  // tx_sign_o, chip_start_o: not needed outside fmt_tx
    fmt_tx #(
        .ROWS(ROWS), .LOG2_N(LOG2_N), .BIN_LO(BIN_LO), .BIN_STEP(BIN_STEP),
        .PHASE_BITS(PHASE_BITS), .SINE_BITS(SINE_BITS), .AMP_BITS(AMP_BITS),
        .DAC_BITS(DAC_BITS), .PN_BITS(PN_BITS), .CHIP_W(CHIP_W), .DELAY_W(DLY_W),
        .ROWS_PER_ENGINE(CPS), .ROW_W(ROW_W)
    ) u_tx (
        .clk(clk), .rst(rst), .ce(ce),
        .pn_enable_i(r_pn_en), .chip_len_i(r_chip_len), .rx_delay_i(r_rx_delay),
        .cfg_we_i(dds_we), .cfg_row_i(dds_row), .cfg_sel_i(dds_sel), .cfg_data_i(dds_data),
        .dac_o(dac), .tx_sign_o(), .rx_sign_o(rx_sign), .chip_start_o());
    /* verilator lint_on PINCONNECTEMPTY */
    assign dac_o = r_run ? dac : {(ROWS*DAC_BITS){1'b0}};

    // ---------------------------------------------------------------- receive
    // M = WINDOWS_M windows per frame: 0 -> 1, above M_MAX -> M_MAX.  The frame's M is
    // latched on the ce edge that takes the last sample of the frame's first window
    // (m_act_q, below) and fed to the receivers from there: they take it when their FFT
    // outputs that window (LATENCY0 < N samples later, before the next latch), so the
    // receivers' frames and this frame-end counter always agree, whenever WINDOWS_M is
    // written.
    localparam [7:0] MMAX8 = M_MAX[7:0];
    wire [7:0]      m_lim;
    wire [7:0]      m_win  = (m_lim == 8'd0) ? 8'd1 : m_lim;
    reg  [7:0]      m_act_q;       // M of the current frame (from its first window's end)
    wire [MC_W-1:0] m_sel  = m_act_q[MC_W-1:0];
    generate
        if (M_MAX < 255) begin : g_m_clamp
            assign m_lim = (r_windows_m > MMAX8) ? MMAX8 : r_windows_m;
            /* verilator lint_off UNUSEDSIGNAL */
            wire unused_m_hi = &{1'b0, m_act_q};  // m_act_q <= M_MAX: its top bits are 0
            /* verilator lint_on UNUSEDSIGNAL */
        end else begin : g_m_full
            assign m_lim = r_windows_m;          // every 8-bit value is a valid M
        end
    endgenerate
    wire                  hm_valid, hm_eof, rx_fft_ovf, rx_sat, rx_overrun;
    wire [ROW_W-1:0]      hm_row;
    wire [15:0]           hm_frame;
    wire [COLS*HM_W-1:0]  hm_data;
    fmt_rx_array #(
        .ROWS(ROWS), .COLS(COLS), .LOG2_N(LOG2_N), .BIN_LO(BIN_LO), .BIN_STEP(BIN_STEP),
        .ADC_BITS(ADC_BITS), .HM_W(HM_W), .FRAME_W(16), .M_MAX(M_MAX),
        .POST_CLK(CPS > 1 ? 1 : 0), .ROW_W(ROW_W), .MC_W(MC_W),
        .CLK_PER_SAMPLE(CPS)
    ) u_rx (
        .clk(clk), .rst(rst), .ce(ce), .adc_i(adc_i), .rx_sign_i(rx_sign), .m_i(m_sel),
        .hm_valid_o(hm_valid), .hm_row_o(hm_row), .hm_frame_o(hm_frame), .hm_data_o(hm_data),
        .hm_eof_o(hm_eof), .fft_ovf_o(rx_fft_ovf), .sat_o(rx_sat), .overrun_o(rx_overrun));

    // frame end of the receive side: the ce edge taking a frame's last ADC sample
    reg [LOG2_N-1:0] samp_q;
    reg [7:0]        win_q;        // window within the frame, 0 .. M-1
    reg [15:0]       fend_num_q;   // number of the frame that ends next
    wire [7:0]       m_now    = (win_q == 8'd0) ? m_win : m_act_q;
    wire             frame_end = ce && (samp_q == N - 1) && (win_q == m_now - 8'd1);
    always @(posedge clk) begin
        if (rst) begin
            samp_q     <= {LOG2_N{1'b0}};
            win_q      <= 8'd0;
            m_act_q    <= 8'd1;
            fend_num_q <= 16'd0;
        end else if (ce) begin
            samp_q <= samp_q + 1'b1;
            if (samp_q == N - 1) begin
                if (win_q == 8'd0) m_act_q <= m_win;
                if (frame_end) begin
                    win_q      <= 8'd0;
                    fend_num_q <= fend_num_q + 1'b1;
                end else begin
                    win_q <= win_q + 1'b1;
                end
            end
        end
    end

    // ---------------------------------------------------------------- touch processing
    wire             ev_valid;
    wire [15:0]      ev_frame;
    wire [1:0]       ev_type;
    wire             ev_last;
    wire [31:0]      now;
    wire             flat_sat, cal_late, lm_ovf, lm_overrun, trk_drop, trk_noslot, trk_overrun, ev_ovf;
    wire             blob_flag;
    wire [15:0]      flat_sat_cnt, lm_drop_cnt, ev_drop_cnt, ev_skip_cnt;
    wire [LIM_W-1:0] limit = ({27'd0, r_limit} > MAX_TOUCHES) ? MAX_TOUCHES[LIM_W-1:0] : r_limit[LIM_W-1:0];

    // calibration read-back: the windows CAL_OFFSET / CAL_GAIN read a copy of the cell
    // at (CAL_ROW, CAL_COL) that a small loop refreshes through fmt_touch's read port
    // (offset, then gain, each answered a few cycles later, in cycles without a
    // heat-map beat): read a window at least 16 cycles after moving the selectors or
    // writing the cell (the control port is far slower than that)
    localparam CAL_W = (HM_W > 16) ? HM_W : 16;
    reg  [1:0]       rb_state_q;                 // 0 ask offset, 1 wait, 2 ask gain, 3 wait
    reg  [15:0]      rb_off_q, rb_gain_q;
    wire             cal_wr   = cal_off_we | cal_gain_we;
    wire             cal_re   = !cal_wr && (rb_state_q == 2'd0 || rb_state_q == 2'd2);
    wire             cal_sel  = cal_wr ? cal_gain_we : (rb_state_q == 2'd2);
    wire             cal_rvalid;
    wire [CAL_W-1:0] cal_rdata;
    always @(posedge clk) begin
        if (rst) begin
            rb_state_q <= 2'd0;
            rb_off_q   <= 16'd0;
            rb_gain_q  <= 16'd0;
        end else begin
            case (rb_state_q)
                2'd0:    if (cal_re) rb_state_q <= 2'd1;
                2'd1:    if (cal_rvalid) begin rb_off_q <= cal_rdata[15:0]; rb_state_q <= 2'd2; end
                2'd2:    if (cal_re) rb_state_q <= 2'd3;
                default: if (cal_rvalid) begin rb_gain_q <= cal_rdata[15:0]; rb_state_q <= 2'd0; end
            endcase
        end
    end
    fmt_touch #(
        .ROWS(ROWS), .COLS(COLS), .HM_W(HM_W), .MAX_TOUCHES(MAX_TOUCHES), .FRAME_W(16),
        .ID_W(8), .TIME_W(32), .EV_DEPTH(EV_DEPTH), .V_W(22), .HOLD_W(12), .CNT_W(16),
        .ROW_IDX_W(ROW_W), .COL_IDX_W(COL_W), .LIM_W(LIM_W), .BLOBS(BLOBS)
    ) u_touch (
        .clk(clk), .rst(rst),
        .threshold_i(r_threshold[HM_W-1:0]), .moore_i(r_mode[0]), .limit_i(limit),
        .bias_en_i(r_mode[1]), .max_jump_i(r_max_jump), .gate_step_i(r_gate_step),
        .hold_off_i(r_hold_off), .vel_shift_i(r_vel_shift), .max_speed_i(r_max_speed),
        .on_thr_i(r_on_thr[HM_W-1:0]), .confirm_i(r_confirm),
        .delay_i(r_lat_dial), .report_period_i(r_report_period),
        .blob_en_i(r_mode[2]), .blob_threshold_i(r_blob_thr[HM_W-1:0]),
        .blob_min_cells_i({4'd0, r_blob_min}),
        .cal_we_i(cal_wr), .cal_sel_i(cal_sel),
        .cal_row_i(r_cal_row[ROW_W-1:0]), .cal_col_i(r_cal_col[COL_W-1:0]),
        .cal_data_i({{(CAL_W - 16){1'b0}}, cal_gain_we ? cal_gain_wdata : cal_off_wdata}),
        .cal_re_i(cal_re), .cal_rvalid_o(cal_rvalid), .cal_rdata_o(cal_rdata),
        .sat_clr_i(sat_clr_we & sat_clr_wd),
        .hm_valid_i(hm_valid), .hm_row_i(hm_row), .hm_frame_i(hm_frame), .hm_data_i(hm_data),
        .hm_eof_i(hm_eof),
        .ev_valid_o(ev_valid), .ev_ready_i(ev_ready_i), .ev_frame_o(ev_frame), .ev_time_o(ev_time_o),
        .ev_id_o(ev_id_o), .ev_type_o(ev_type), .ev_x_o(ev_x_o), .ev_y_o(ev_y_o),
        .ev_strength_o(ev_strength_o), .ev_axis_major_o(ev_axis_major_o),
        .ev_axis_minor_o(ev_axis_minor_o), .ev_angle_o(ev_angle_o), .ev_flags_o(ev_flags_o),
        .ev_last_o(ev_last),
        .now_o(now), .sat_flag_o(flat_sat), .cal_late_o(cal_late), .sat_count_o(flat_sat_cnt),
        .lm_overflow_o(lm_ovf), .lm_drop_count_o(lm_drop_cnt), .lm_overrun_o(lm_overrun),
        .trk_drop_o(trk_drop), .trk_noslot_o(trk_noslot), .trk_overrun_o(trk_overrun),
        .ev_drop_count_o(ev_drop_cnt), .ev_skip_count_o(ev_skip_cnt), .ev_overflow_o(ev_ovf),
        .blob_flag_o(blob_flag));
    assign ev_valid_o = ev_valid;
    assign ev_frame_o = ev_frame;
    assign ev_type_o  = ev_type;
    assign ev_last_o  = ev_last;
    wire ev_fire = ev_valid & ev_ready_i;

    // ---------------------------------------------------------------- latency counters
    wire [15:0] lf_last, lf_min, lf_max, ll_last, ll_min, ll_max, lt_last, lt_min, lt_max;
    wire [31:0] lf_count, ll_count, lt_count, hist_data;
    wire        lt_armed, lat_sat;
    fmt_latency #(
        .CNT_W(16), .NUM_W(32), .FRAME_SLOTS_W(2), .HIST_BINS_W(4), .HIST_SHIFT(5), .TIME_W(32)
    ) u_lat (
        .clk(clk), .rst(rst), .clear_i(lat_clr_we & lat_clr_wd),
        .frame_end_i(frame_end), .frame_end_slot_i(fend_num_q[1:0]),
        .ev_fire_i(ev_fire), .ev_slot_i(ev_frame[1:0]), .ev_last_i(ev_last),
        .ev_new_i(ev_type == 2'd0), .trig_i(trig_i),
        .first_last_o(lf_last), .first_min_o(lf_min), .first_max_o(lf_max), .first_count_o(lf_count),
        .last_last_o(ll_last), .last_min_o(ll_min), .last_max_o(ll_max), .last_count_o(ll_count),
        .trig_last_o(lt_last), .trig_min_o(lt_min), .trig_max_o(lt_max), .trig_count_o(lt_count),
        .trig_armed_o(lt_armed),
        .hist_sel_i(blk_addr[4]), .hist_addr_i(blk_addr[3:0]), .hist_data_o(hist_data),
        .sat_o(lat_sat));

    // ---------------------------------------------------------------- heat-map snapshot
    reg  [COLS*HM_W-1:0] snap_mem [0:ROWS-1];
    reg                  snap_arm_q, snap_cap_q, snap_done_q;
    reg  [15:0]          snap_frame_q;
    always @(posedge clk) begin
        if (rst) begin
            snap_arm_q   <= 1'b0;
            snap_cap_q   <= 1'b0;
            snap_done_q  <= 1'b0;
            snap_frame_q <= 16'd0;
        end else begin
            if (snap_we && snap_wd) begin
                snap_arm_q  <= 1'b1;
                snap_done_q <= 1'b0;
            end else if (hm_eof && snap_arm_q) begin
                snap_arm_q <= 1'b0;          // the next frame is captured
                snap_cap_q <= 1'b1;
            end else if (hm_eof && snap_cap_q) begin
                snap_cap_q   <= 1'b0;
                snap_done_q  <= 1'b1;
                snap_frame_q <= hm_frame;
            end
        end
    end
    always @(posedge clk) begin
        if (snap_cap_q && hm_valid) snap_mem[hm_row] <= hm_data;
    end
    wire [31:0] snap_status = {snap_done_q, snap_arm_q | snap_cap_q, 14'd0, snap_frame_q};

    // block read: BLK_LAT = 3
    localparam RSH   = 20;
    localparam RECIP = ((1 << RSH) + COLS - 1) / COLS;   // exact row = addr / COLS for addr < 2^16 / ... (CELLS <= 4096)
    reg  [15:0]          b1_addr_q;
    reg  [ROW_W-1:0]     b1_row_q;
    reg                  b1_snap_q, b1_hist_q, b2_snap_q, b2_hist_q;
    reg  [COL_W-1:0]     b2_col_q;
    reg  [COLS*HM_W-1:0] b2_rowdata_q;
    reg  [31:0]          b2_hist_q_d, blk_rdata_q;
    wire [35:0]          row_prod = blk_addr * RECIP;
    wire [15:0]          b1_rowx  = {{(16 - ROW_W){1'b0}}, b1_row_q};
    wire [15:0]          b1_col   = b1_addr_q - b1_rowx * COLS16;
    always @(posedge clk) begin
        // stage 1: row index and window decode (hist_data_o is registered in fmt_latency)
        b1_addr_q <= blk_addr;
        b1_row_q  <= row_prod[RSH +: ROW_W];
        b1_snap_q <= blk_req && (blk_addr < CELLS16);
        b1_hist_q <= blk_req && (blk_addr[15:5] == 11'h400);
        // stage 2: row read and column
        b2_rowdata_q <= snap_mem[b1_row_q];
        b2_col_q     <= b1_col[COL_W-1:0];
        b2_snap_q    <= b1_snap_q;
        b2_hist_q    <= b1_hist_q;
        b2_hist_q_d  <= hist_data;
        // stage 3: column select
        if (b2_snap_q)      blk_rdata_q <= {{(32 - HM_W){1'b0}}, b2_rowdata_q[b2_col_q*HM_W +: HM_W]};
        else if (b2_hist_q) blk_rdata_q <= b2_hist_q_d;
        else                blk_rdata_q <= 32'd0;
    end
    wire unused_prod = &{1'b0, row_prod, b1_col};

    // ---------------------------------------------------------------- status
    reg [15:0] frame_count_q;
    always @(posedge clk) begin
        if (rst)         frame_count_q <= 16'd0;
        else if (hm_eof) frame_count_q <= frame_count_q + 1'b1;
    end
    reg [31:0] frames_q;
    always @(posedge clk) begin
        if (rst)         frames_q <= 32'd0;
        else if (hm_eof) frames_q <= frames_q + 1'b1;
    end
    assign frame_count_o = frame_count_q;
    wire [10:0] status_set = {rx_overrun, rx_sat, cal_late, blob_flag,
                              trk_drop | trk_noslot | trk_overrun, lm_ovf | lm_overrun,
                              err_pulse, lat_sat, ev_ovf, rx_fft_ovf, flat_sat};
    assign status_o = r_status;

    // ---------------------------------------------------------------- control port
    // event payload, protocol.pack_event: frame(2) time(4) id(1) type_last(1) x(2) y(2)
    // strength(4) axis_major(2) axis_minor(2) angle(1) flags(1) reserved(2)
    wire [191:0] evs_data = {ev_frame, ev_time_o, ev_id_o, ev_last, 5'd0, ev_type, ev_x_o, ev_y_o,
                             {{(32 - HM_W){1'b0}}, ev_strength_o}, ev_axis_major_o,
                             ev_axis_minor_o, ev_angle_o, ev_flags_o, 16'd0};
    // The UART stream is a monitor tap of the event port's handshake: a report FIFO holds
    // an admitted frame's events until the port has sent them, and drops a frame whole
    // (STREAM_DROP_COUNT) while a report waits or when it does not fit, so the host gets
    // neither half a report nor a stale one.
    wire         evs_valid, evs_ready;
    wire [191:0] evs_q;
    wire [15:0]  stream_drop_cnt;
    /* verilator lint_off PINCONNECTEMPTY */  // drop_o: the count is what the host reads
    fmt_report_fifo #(.W(192), .AW(STREAM_AW)) u_stream (
        .clk(clk), .rst(rst), .en_i(stream_en), .in_valid_i(ev_fire), .in_data_i(evs_data),
        .in_last_i(ev_last), .out_valid_o(evs_valid), .out_data_o(evs_q), .out_ready_i(evs_ready),
        .drop_o(), .drop_count_o(stream_drop_cnt));
    /* verilator lint_on PINCONNECTEMPTY */
    fmt_ctrl_port #(
        .DIV(UART_DIV), .TIMEOUT_BITS(UART_TIMEOUT), .BLK_LAT(3), .EV_BYTES(24),
        .REGMAP_ID(REGMAP_ID), .ROWS(ROWS), .COLS(COLS), .LOG2_N(LOG2_N), .HM_W(HM_W),
        .BIN_LO(BIN_LO), .BIN_STEP(BIN_STEP)
    ) u_ctrl (
        .clk(clk), .rst(rst), .rxd_i(uart_rx_i), .txd_o(uart_tx_o),
        .reg_we_o(u_we), .reg_re_o(u_re), .reg_addr_o(u_addr), .reg_wdata_o(u_wdata),
        .reg_rdata_i(reg_rdata), .blk_req_o(blk_req), .blk_addr_o(blk_addr),
        .blk_rdata_i(blk_rdata_q), .evs_valid_i(evs_valid), .evs_data_i(evs_q),
        .evs_ready_o(evs_ready), .stream_en_o(stream_en), .err_count_o(err_count),
        .err_last_o(err_last), .err_pulse_o(err_pulse));

    /* verilator lint_off PINCONNECTEMPTY */  // rw registers the core does not use
    fmt_regfile u_regs (
        .clk(clk), .rst(rst), .reg_we_i(reg_we), .reg_re_i(reg_re), .reg_addr_i(reg_addr),
        .reg_wdata_i(reg_wdata), .reg_rdata_o(reg_rdata),
        .scratch_o(r_scratch), .run_o(r_run), .pn_enable_o(r_pn_en), .pn_chip_len_o(r_chip_len),
        .pn_rx_delay_o(r_rx_delay), .windows_m_o(r_windows_m), .tone_sel_o(r_tone_sel),
        .tone_tw_we_o(tone_tw_we), .tone_tw_wdata_o(tone_tw_wdata), .tone_tw_re_o(tone_tw_re),
        .tone_tw_rdata_i(tone_tw_rdata),
        .tone_amp_we_o(tone_amp_we), .tone_amp_wdata_o(tone_amp_wdata), .tone_amp_re_o(tone_amp_re),
        .tone_amp_rdata_i(tone_amp_rdata),
        .touch_threshold_o(r_threshold), .touch_mode_o(r_mode), .contact_limit_o(r_limit),
        .track_max_jump_o(r_max_jump), .track_gate_step_o(r_gate_step),
        .track_hold_off_o(r_hold_off), .track_vel_shift_o(r_vel_shift),
        .track_max_speed_o(r_max_speed), .blob_threshold_o(r_blob_thr),
        .blob_min_cells_o(r_blob_min), .touch_on_threshold_o(r_on_thr),
        .track_confirm_o(r_confirm), .cal_row_o(r_cal_row), .cal_col_o(r_cal_col),
        .cal_offset_we_o(cal_off_we), .cal_offset_wdata_o(cal_off_wdata), .cal_offset_re_o(cal_off_re),
        .cal_offset_rdata_i(rb_off_q),
        .cal_gain_we_o(cal_gain_we), .cal_gain_wdata_o(cal_gain_wdata), .cal_gain_re_o(cal_gain_re),
        .cal_gain_rdata_i(rb_gain_q),
        .latency_dial_o(r_lat_dial), .report_period_o(r_report_period),
        .frame_count_i(frames_q), .status_set_i(status_set), .status_o(r_status),
        .ctrl_errors_i(err_count), .ctrl_last_err_i(err_last),
        .ev_drop_count_i(ev_drop_cnt), .ev_skip_count_i(ev_skip_cnt),
        .flat_sat_count_i(flat_sat_cnt), .lm_drop_count_i(lm_drop_cnt),
        .stream_drop_count_i(stream_drop_cnt), .sat_clear_we_o(sat_clr_we), .sat_clear_wdata_o(sat_clr_wd),
        .lat_first_last_i(lf_last), .lat_first_min_i(lf_min), .lat_first_max_i(lf_max),
        .lat_first_count_i(lf_count),
        .lat_last_last_i(ll_last), .lat_last_min_i(ll_min), .lat_last_max_i(ll_max),
        .lat_last_count_i(ll_count),
        .lat_trig_last_i(lt_last), .lat_trig_min_i(lt_min), .lat_trig_max_i(lt_max),
        .lat_trig_count_i(lt_count), .lat_trig_armed_i(lt_armed),
        .lat_clear_we_o(lat_clr_we), .lat_clear_wdata_o(lat_clr_wd),
        .snap_req_we_o(snap_we), .snap_req_wdata_o(snap_wd), .snap_status_i(snap_status));
    /* verilator lint_on PINCONNECTEMPTY */

    // settings the core does not use (documented in the header)
    wire unused_ok = &{1'b0, r_scratch, tone_tw_re, tone_amp_re,
                       cal_off_re, cal_gain_re, r_threshold, r_cal_row, r_cal_col, r_limit,
                       tone_tw_wdata, tone_amp_wdata, stream_en, now,
                       r_tone_sel, blk_addr, r_max_speed};
endmodule

`default_nettype wire
