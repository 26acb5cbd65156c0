// fmt_core_sim_top -- SIMULATION-ONLY full-chain top: fmt_core + fmt_channel_sim (the
// DAC words through the channel delay and a coupling matrix with stamped updates, plus
// counter-based noise, DC offset, interferers and charger noise, clipped, ENOB-masked, back into the
// ADC inputs; effects from CHAN_FILE / GAUSS_FILE / SINE_FILE) + a coupling-update
// player + loggers, so that a whole scene runs with no testbench code on the
// per-sample path.
//
// Coupling-update player (runs while play_i = 1): UPD_FILE ($readmemh, 64-bit records, UPD_LEN entries) is
// executed from the first cycle after reset, one record per cycle:
//   [63:60] = 1  write G_pending[row = [59:52]][col = [51:44]] = [15:0]
//   [63:60] = 3  write the pending charger weight W_pending[col = [51:44]] = [15:0]
//   [63:60] = 2  commit the pending matrix, stamped with sample [31:0]; the player then
//                waits until the channel has copied it (its armed flag clears) before the
//                next record, so the next writes cannot reach the armed copy
//   [63:60] = 0  end (the player stops)
// Records before the first commit may be written while rst is high (the initial matrix);
// a commit is only issued with rst low.  The generator (bench/core/run_sim_rtl.py) spaces the
// commits so that every one is issued before its stamp; upd_late_o counts commits issued
// at or after their stamp (the run must report 0).
//
// Loggers ($fwrite, "" = off): HM_LOG one line per heat-map beat "R <cycle> <row>
// <frame> <hex data>" and per end of frame "E <cycle> <frame>"; EV_LOG one line per event
// leaving the parallel port "V <cycle> <frame> <id> <type> <x> <y> <strength> <major>
// <minor> <angle> <flags> <last> <time>"; FE_LOG one line per receiver frame end (last ADC
// sample of a frame taken) "F <cycle> <frame>".  <cycle> = clk edges since reset (the
// first edge with rst low is cycle 0).  The loggers and counters run while play_i = 1.  Logs are flushed when flush_i is high.
// Ports: the core's control ports are passed through (clock, reset, UART, local bus,
// trigger, event ready).
//
// EXT_CHANNEL = 1 (the standalone C++ harness bench/core/sim_main.cpp, `make sim`):
// no fmt_channel_sim and no player; the core's ADC inputs come from adc_ext_i and the
// harness computes them from ce_o / dac_o itself (the same formula, bit-exact, in C++:
// a 30 x 40 matrix product per sample is far cheaper there); upd_late_o, upd_done_o
// and clip_o are then 0 / 1 / 0 (the harness counts them).  EXT_CHANNEL = 0 (cocotb
// tests): the Verilog channel and player as described above; adc_ext_i is unused.
`default_nettype none
`include "fmt_defaults.vh"

module fmt_core_sim_top #(
    parameter ROWS           = `FMT_ROWS,        // sensor rows
    parameter COLS           = `FMT_COLS,        // sensor columns
    parameter LOG2_N         = `FMT_LOG2_N,      // FFT size
    parameter BIN_LO         = `FMT_BIN_LO,      // bin of row 0
    parameter HM_W           = `FMT_HM_W,        // heat-map cell width
    parameter MAX_TOUCHES    = `FMT_MAX_TOUCHES, // contact limit
    parameter CLK_PER_SAMPLE = 3,                // clk cycles per sample
    parameter EV_DEPTH       = 2048,             // event FIFO depth
    parameter UART_DIV       = 8,                // clk cycles per UART bit
    parameter CHAN_FILE      = "",               // channel effects ($readmemh, fmt_channel_sim), "" = none
    parameter GAUSS_FILE     = "",               // the noise generator's Gaussian table
    parameter SINE_FILE      = "",               // the interferers' sine table
    parameter UPD_LEN        = 1,                // coupling-update records
    parameter UPD_FILE       = "",               // coupling-update records ($readmemh), "" = none
    parameter HM_LOG         = "",               // heat-map log file
    parameter EV_LOG         = "",               // event log file
    parameter FE_LOG         = "",               // frame-end log file
    parameter EXT_CHANNEL    = 0,                // 1: ADC words from adc_ext_i (C++ channel)
    parameter BLOBS          = 1                 // fmt_core BLOBS: 0 = no blob detector
) (
    input  wire        clk,          // processing clock
    input  wire        rst,          // synchronous reset of core and channel
    input  wire        ev_ready_i,   // event consumer ready
    input  wire        trig_i,       // external trigger
    input  wire        uart_rx_i,    // UART into the core
    output wire        uart_tx_o,    // UART out of the core
    input  wire        bus_we_i,     // local bus write
    input  wire        bus_re_i,     // local bus read
    input  wire [15:0] bus_addr_i,   // local bus address
    input  wire [31:0] bus_wdata_i,  // local bus write data
    output wire [31:0] bus_rdata_o,  // local bus read data
    input  wire        flush_i,      // flush the log files
    input  wire        play_i,       // 1: the update player and the loggers run
    output reg  [31:0] cycle_o,      // clk edges since reset
    output reg  [31:0] frames_o,     // heat-map frames since reset
    output reg  [31:0] events_o,     // events since reset
    output reg  [31:0] upd_late_o,   // commits issued at or after their stamp
    output wire        upd_done_o,   // the player reached the end record
    output wire        clip_o,       // the channel clipped (sticky)
    output wire        ce_o,         // the core's sample strobe (for the C++ channel)
    output wire [ROWS*`FMT_DAC_BITS-1:0] dac_o,      // the core's DAC words (row r at [r*12 +: 12])
    input  wire [COLS*`FMT_ADC_BITS-1:0] adc_ext_i   // ADC words when EXT_CHANNEL = 1
);
    localparam ROW_W = (ROWS > 1) ? $clog2(ROWS) : 1;
    localparam COL_W = (COLS > 1) ? $clog2(COLS) : 1;

    wire                     ce;
    wire [ROWS*`FMT_DAC_BITS-1:0] dac;
    wire [COLS*`FMT_ADC_BITS-1:0] adc;
    wire                     ev_valid, ev_last;
    wire [15:0]              ev_frame, ev_x, ev_y, ev_maj, ev_min;
    wire [31:0]              ev_time;
    wire [7:0]               ev_id, ev_angle, ev_flags;
    wire [1:0]               ev_type;
    wire [HM_W-1:0]          ev_strength;
    wire [8:0]               status;
    wire [15:0]              frame_count;

    fmt_core #(
        .ROWS(ROWS), .COLS(COLS), .LOG2_N(LOG2_N), .BIN_LO(BIN_LO), .HM_W(HM_W),
        .MAX_TOUCHES(MAX_TOUCHES), .CLK_PER_SAMPLE(CLK_PER_SAMPLE), .EV_DEPTH(EV_DEPTH),
        .UART_DIV(UART_DIV), .UART_TIMEOUT(20), .BLOBS(BLOBS)
    ) u_core (
        .clk(clk), .rst(rst), .ce_o(ce), .dac_o(dac), .adc_i(adc),
        .ev_valid_o(ev_valid), .ev_ready_i(ev_ready_i), .ev_frame_o(ev_frame), .ev_time_o(ev_time),
        .ev_id_o(ev_id), .ev_type_o(ev_type), .ev_x_o(ev_x), .ev_y_o(ev_y),
        .ev_strength_o(ev_strength), .ev_axis_major_o(ev_maj), .ev_axis_minor_o(ev_min),
        .ev_angle_o(ev_angle), .ev_flags_o(ev_flags), .ev_last_o(ev_last), .trig_i(trig_i),
        .uart_rx_i(uart_rx_i), .uart_tx_o(uart_tx_o),
        .bus_we_i(bus_we_i), .bus_re_i(bus_re_i), .bus_addr_i(bus_addr_i),
        .bus_wdata_i(bus_wdata_i), .bus_rdata_o(bus_rdata_o),
        .status_o(status), .frame_count_o(frame_count));

    assign ce_o  = ce;
    assign dac_o = dac;

    // ---------------------------------------------------------------- channel + player
    generate if (EXT_CHANNEL != 0) begin : g_ext
        assign adc        = adc_ext_i;
        assign upd_done_o = 1'b1;
        assign clip_o     = 1'b0;
        always @(posedge clk) upd_late_o <= 32'd0;
    end else begin : g_ch
        reg  [63:0]      upd_mem [0:UPD_LEN-1];
        reg  [31:0]      upd_ptr_q;
        reg              upd_wait_q;
        reg              upd_we, upd_chg, upd_commit;
        reg  [ROW_W-1:0] upd_row;
        reg  [COL_W-1:0] upd_col;
        reg  [15:0]      upd_data;
        reg  [31:0]      upd_stamp;
        wire [31:0]      ch_sample;
        wire             ch_clip;
        integer          k;
        initial begin
            for (k = 0; k < UPD_LEN; k = k + 1) upd_mem[k] = 64'd0;
            if (UPD_FILE != "") $readmemh(UPD_FILE, upd_mem);
            upd_ptr_q  = 32'd0;
            upd_wait_q = 1'b0;
        end
        wire [63:0] rec  = (upd_ptr_q < UPD_LEN) ? upd_mem[upd_ptr_q] : 64'd0;
        wire [3:0]  kind = rec[63:60];
        assign upd_done_o = (kind == 4'd0);
        always @(*) begin
            upd_we     = 1'b0;
            upd_chg    = 1'b0;
            upd_commit = 1'b0;
            upd_row    = rec[52 +: ROW_W];
            upd_col    = rec[44 +: COL_W];
            upd_data   = rec[15:0];
            upd_stamp  = rec[31:0];
            if (play_i && !upd_wait_q) begin
                if (kind == 4'd1 || kind == 4'd3) upd_we = 1'b1;
                if (kind == 4'd3) upd_chg = 1'b1;
                if (kind == 4'd2 && !rst) upd_commit = 1'b1;
            end
        end
        always @(posedge clk) begin
            if (upd_wait_q) begin
                if (!u_ch.armed_q) upd_wait_q <= 1'b0;
            end else if (upd_we) begin
                upd_ptr_q <= upd_ptr_q + 32'd1;
            end else if (upd_commit) begin
                upd_ptr_q  <= upd_ptr_q + 32'd1;
                upd_wait_q <= 1'b1;
            end
        end
        always @(posedge clk) begin
            if (rst) upd_late_o <= 32'd0;
            // the copy happens at the first ce edge with sample >= stamp: late if that edge
            // has passed already (next sample index > stamp)
            else if (upd_commit && upd_stamp != 32'd0 &&
                     (u_ch.k_q > upd_stamp || (u_ch.k_q == upd_stamp && ce))) upd_late_o <= upd_late_o + 32'd1;
        end

        fmt_channel_sim #(
            .ROWS(ROWS), .COLS(COLS), .DAC_BITS(`FMT_DAC_BITS), .ADC_BITS(`FMT_ADC_BITS), .COUP_BITS(16), .COUP_FRAC(16),
            .NOISE_BITS(16), .NOISE_FRAC(4), .NOISE_LEN(1), .NOISE_FILE(""),
            .CHAN_FILE(CHAN_FILE), .GAUSS_FILE(GAUSS_FILE), .SINE_FILE(SINE_FILE)
        ) u_ch (
            .clk(clk), .rst(rst), .ce(ce), .dac_i(dac),
            .upd_we_i(upd_we), .upd_chg_i(upd_chg), .upd_row_i(upd_row), .upd_col_i(upd_col), .upd_data_i(upd_data),
            .upd_commit_i(upd_commit), .upd_stamp_i(upd_stamp),
            .adc_o(adc), .clip_o(ch_clip), .clip_sticky_o(clip_o), .sample_o(ch_sample));
        wire unused_ch = &{1'b0, ch_sample, ch_clip, rec};
    end endgenerate

    // ---------------------------------------------------------------- counters + logs
    integer fh_hm, fh_ev, fh_fe;
    initial begin
        fh_hm = 0; fh_ev = 0; fh_fe = 0;
        if (HM_LOG != "") fh_hm = $fopen(HM_LOG, "w");
        if (EV_LOG != "") fh_ev = $fopen(EV_LOG, "w");
        if (FE_LOG != "") fh_fe = $fopen(FE_LOG, "w");
    end
    always @(posedge clk) begin
        if (rst) begin
            cycle_o  <= 32'd0;
            frames_o <= 32'd0;
            events_o <= 32'd0;
        end else if (play_i) begin
            cycle_o <= cycle_o + 32'd1;
            if (u_core.hm_eof) frames_o <= frames_o + 32'd1;
            if (ev_valid && ev_ready_i) events_o <= events_o + 32'd1;
            if (fh_hm != 0 && u_core.hm_valid)
                $fwrite(fh_hm, "R %0d %0d %0d %h\n", cycle_o, u_core.hm_row, u_core.hm_frame, u_core.hm_data);
            if (fh_hm != 0 && u_core.hm_eof)
                $fwrite(fh_hm, "E %0d %0d\n", cycle_o, u_core.hm_frame);
            if (fh_ev != 0 && ev_valid && ev_ready_i)
                $fwrite(fh_ev, "V %0d %0d %0d %0d %0d %0d %0d %0d %0d %0d %0d %0d %0d\n", cycle_o,
                        ev_frame, ev_id, ev_type, ev_x, ev_y, ev_strength, ev_maj, ev_min,
                        ev_angle, ev_flags, ev_last, ev_time);
            if (fh_fe != 0 && u_core.frame_end)
                $fwrite(fh_fe, "F %0d %0d\n", cycle_o, u_core.fend_num_q);
        end
        if (flush_i) begin
            if (fh_hm != 0) $fflush(fh_hm);
            if (fh_ev != 0) $fflush(fh_ev);
            if (fh_fe != 0) $fflush(fh_fe);
        end
    end
    wire unused_ok = &{1'b0, status, frame_count, adc_ext_i};
endmodule

`default_nettype wire
