// fpga_core -- portable board core of the XC5VSX95T build: fmt_core, the ADS5272-class
// receive side (fmt_adc_deser: lane training over the ADCs' serial control port, word
// alignment, the words of all columns to fmt_core's adc_i), the AD9834-class transmit
// side (fmt_dds_prog: tone plan over SPI, PN on the chips' PSELECT), the internal DDS
// bank's words on a DAC port, UART, trigger and LEDs.  No vendor primitive: fpga.v holds
// the IBUFDS / ISERDES / IODELAY / PLL / BUFG and feeds the per-lane bits here (SER_W
// bits per clk, the earliest at the top).
//
// Clocking: one clock clk = 3 x fs from the PLL locked to the ADC bit clock (fpga.v);
// the ISERDES deliver in clk (CLKDIV = clk), so no domain crossing is left here.
// Reset: rst (synchronous, from fpga.v's synchroniser) restarts the training and the DDS
// programming; fmt_core stays in reset until the ADC lanes are trained, so its sample 0
// (first ce) is a fixed number of clk after the first trained word (tb/fpga_xc5v).
// PN on the chips: fmt_core does not export its transmit PN sign yet, so a second
// fmt_pn_gen here runs from the same reset and ce with fmt_core's PN reset settings
// (enable 1, chip length 1); it equals the core's sign as long as PN_ENABLE and
// PN_CHIP_LEN keep their reset values (issue #13; an export port on fmt_core lifts this).
// PN_RX_DELAY must be written with the chain's delay (README: DDS pipeline + ADC latency
// + this receive path).
// DAC port: dac_o = fmt_core dac_o (row r at [r*DAC_BITS +: DAC_BITS], signed, new word
// after each dac_ce_o) for boards that carry DACs instead of DDS chips.
// LEDs: 0 heartbeat (1.9 Hz at 125 MHz), 1 ADC trained, 2 DDS programmed, 3 training
// restarted, 4 frame lane lost, 5..7 fmt_core status bits 0..2.
`default_nettype none
`include "fmt_defaults.vh"

module fpga_core #(
    parameter ROWS        = `FMT_ROWS,        // transmit rows = DDS chips
    parameter COLS        = `FMT_COLS,        // receive columns = ADC data lanes
    parameter LOG2_N      = `FMT_LOG2_N,      // FFT size N = 2^LOG2_N
    parameter BIN_LO      = `FMT_BIN_LO,      // FFT bin of row 0
    parameter BIN_STEP    = `FMT_BIN_STEP,    // bins between rows
    parameter HM_W        = `FMT_HM_W,        // heat-map cell width
    parameter MAX_TOUCHES = `FMT_MAX_TOUCHES, // contact limit
    parameter ADC_BITS    = `FMT_ADC_BITS,    // ADC word width (12: ADS5272)
    parameter DAC_BITS    = `FMT_DAC_BITS,    // DAC port word width per row
    parameter PHASE_BITS  = `FMT_PHASE_BITS,  // DDS phase accumulator width (fmt_core)
    parameter SINE_BITS   = `FMT_SINE_BITS,   // DDS sine table width (fmt_core)
    parameter AMP_BITS    = `FMT_AMP_BITS,    // DDS amplitude width (fmt_core)
    parameter PN_BITS     = `FMT_PN_BITS,     // PN LFSR length (as fmt_core)
    parameter CLK_PER_SAMPLE = 3,             // clk per ADC sample; the lanes give ADC_BITS / CLK_PER_SAMPLE bits per clk
    parameter M_MAX       = 255,              // largest windows per frame (fmt_core)
    parameter CH_PER_CHIP = 8,                // ADC channels per chip
    parameter CHIPS       = (COLS + CH_PER_CHIP - 1) / CH_PER_CHIP,  // ADC chips
    parameter SER_W       = ADC_BITS / CLK_PER_SAMPLE,  // ISERDES bits per lane per clk (4 at 3 clk per sample)
    parameter TAPS        = 64,               // IODELAY taps
    parameter DWELL       = 16,               // word periods judged per tap
    parameter SETTLE      = 64,               // word periods after an ADC register write
    parameter MCLK_LOG2   = 0,                // DDS MCLK = fs * 2^MCLK_LOG2
    parameter SPI_DIV     = 4,                // clk per SCLK half period, both SPI buses
    parameter [15:0] TP_DESKEW = 16'hA001,    // ADC register word: deskew pattern (PLACEHOLDER, README)
    parameter [15:0] TP_SYNC   = 16'hA002,    // ADC register word: sync pattern (PLACEHOLDER, README)
    parameter [15:0] TP_NORMAL = 16'hA000,    // ADC register word: normal data (PLACEHOLDER, README)
    parameter LSB_FIRST   = 0,                // 1: the ADC lanes send the LSB first
    parameter UART_DIV    = 1085,             // clk per UART bit (125 MHz: 115200 baud)
    parameter UART_TIMEOUT = 40,              // control-port inter-byte timeout, bit times
    parameter EV_DEPTH    = 2048,             // event FIFO entries
    parameter BLOBS       = 1,                // blob detector built
    parameter HB_BITS     = 26                // heartbeat counter width (LED 0 = its MSB)
) (
    input  wire                      clk,             // 3 x fs
    input  wire                      rst,             // synchronous, active high
    // ADS5272-class ADCs (bits from fpga.v's ISERDES) and their control
    input  wire [COLS*SER_W-1:0]     adc_data_bits_i, // data lane c at [c*SER_W +: SER_W]
    input  wire [CHIPS*SER_W-1:0]    adc_frame_bits_i,// frame lane of chip k
    output wire                      adc_dly_rst_o,   // IODELAY reset (all lanes)
    output wire [COLS+CHIPS-1:0]     adc_dly_ce_o,    // IODELAY step per lane (data, then frame lanes)
    output wire                      adc_dly_inc_o,   // IODELAY step direction
    output wire                      adc_sclk_o,      // ADC serial control port (shared)
    output wire                      adc_sdata_o,
    output wire                      adc_cs_n_o,
    // AD9834-class DDS chips
    output wire                      dds_sclk_o,
    output wire [ROWS-1:0]           dds_sdata_o,     // one per chip
    output wire                      dds_fsync_n_o,
    output wire                      dds_psel_o,      // PN on PSELECT (all chips)
    output wire                      dds_fsel_o,
    output wire                      dds_reset_o,
    // DAC port (the internal DDS bank)
    output wire [ROWS*DAC_BITS-1:0]  dac_o,
    output wire                      dac_ce_o,
    // host
    input  wire                      uart_rx_i,
    output wire                      uart_tx_o,
    input  wire                      trig_i,
    output wire [7:0]                led_o
);
    // ---------------------------------------------------------------- receive
    wire [COLS*ADC_BITS-1:0] adc_words;
    wire adc_trained, adc_err, adc_lost, adc_stb;
    fmt_adc_deser #(
        .COLS(COLS), .CH_PER_CHIP(CH_PER_CHIP), .CHIPS(CHIPS), .ADC_BITS(ADC_BITS),
        .SER_W(SER_W), .TAPS(TAPS), .DWELL(DWELL), .MIN_EYE(4), .LOCK(16), .SETTLE(SETTLE),
        .SPI_DIV(SPI_DIV), .TP_DESKEW(TP_DESKEW), .TP_SYNC(TP_SYNC), .TP_NORMAL(TP_NORMAL),
        .SYNC_WORD(12'hFC0), .LSB_FIRST(LSB_FIRST)
    ) u_deser (
        .clk(clk), .rst(rst), .train_i(1'b0),
        .data_bits_i(adc_data_bits_i), .frame_bits_i(adc_frame_bits_i),
        .adc_o(adc_words), .word_stb_o(adc_stb), .trained_o(adc_trained),
        .err_o(adc_err), .lost_o(adc_lost),
        .dly_rst_o(adc_dly_rst_o), .dly_ce_o(adc_dly_ce_o), .dly_inc_o(adc_dly_inc_o),
        .spi_sclk_o(adc_sclk_o), .spi_sdata_o(adc_sdata_o), .spi_cs_n_o(adc_cs_n_o));

    // fmt_core leaves reset on a word strobe once the lanes are trained
    reg core_rst_q;
    always @(posedge clk) begin
        if (rst)                       core_rst_q <= 1'b1;
        else if (adc_trained && adc_stb) core_rst_q <= 1'b0;
    end

    // ---------------------------------------------------------------- core
    wire        ce;
    wire [10:0] status;
    /* verilator lint_off PINCONNECTEMPTY */  // event fields: the UART streams them
    fmt_core #(
        .ROWS(ROWS), .COLS(COLS), .LOG2_N(LOG2_N), .BIN_LO(BIN_LO), .BIN_STEP(BIN_STEP),
        .ADC_BITS(ADC_BITS), .DAC_BITS(DAC_BITS), .PHASE_BITS(PHASE_BITS),
        .SINE_BITS(SINE_BITS), .AMP_BITS(AMP_BITS), .PN_BITS(PN_BITS), .HM_W(HM_W),
        .MAX_TOUCHES(MAX_TOUCHES), .CLK_PER_SAMPLE(CLK_PER_SAMPLE), .M_MAX(M_MAX),
        .EV_DEPTH(EV_DEPTH), .BLOBS(BLOBS), .UART_DIV(UART_DIV), .UART_TIMEOUT(UART_TIMEOUT)
    ) u_core (
        .clk(clk), .rst(core_rst_q), .ce_o(ce), .dac_o(dac_o), .adc_i(adc_words),
        .ev_valid_o(), .ev_ready_i(1'b1), .ev_frame_o(), .ev_time_o(), .ev_id_o(),
        .ev_type_o(), .ev_x_o(), .ev_y_o(), .ev_strength_o(), .ev_axis_major_o(),
        .ev_axis_minor_o(), .ev_angle_o(), .ev_flags_o(), .ev_last_o(),
        .trig_i(trig_i), .uart_rx_i(uart_rx_i), .uart_tx_o(uart_tx_o),
        .bus_we_i(1'b0), .bus_re_i(1'b0), .bus_addr_i(16'd0), .bus_wdata_i(32'd0),
        .bus_rdata_o(), .status_o(status), .frame_count_o());
    /* verilator lint_on PINCONNECTEMPTY */
    assign dac_ce_o = ce;

    // ---------------------------------------------------------------- transmit
    // fmt_core's PN twin (reset settings, see header)
    wire pn_tx;
    /* verilator lint_off PINCONNECTEMPTY */  // receive sign, chip start: fmt_core's own
    fmt_pn_gen #(.PN_BITS(PN_BITS), .TAPS(15'h6000), .SEED(1), .CHIP_W(10), .DELAY_W(6)) u_pn (
        .clk(clk), .rst(core_rst_q), .ce(ce), .enable_i(1'b1), .chip_len_i(10'd1),
        .rx_delay_i(6'd0), .tx_sign_o(pn_tx), .rx_sign_o(), .chip_start_o());
    /* verilator lint_on PINCONNECTEMPTY */
    wire dds_done;
    fmt_dds_prog #(
        .ROWS(ROWS), .LOG2_N(LOG2_N), .BIN_LO(BIN_LO), .BIN_STEP(BIN_STEP),
        .MCLK_LOG2(MCLK_LOG2), .SPI_DIV(SPI_DIV)
    ) u_dds (
        .clk(clk), .rst(rst), .ce(ce), .start_i(1'b0), .pn_sign_i(pn_tx),
        .sclk_o(dds_sclk_o), .sdata_o(dds_sdata_o), .fsync_n_o(dds_fsync_n_o),
        .psel_o(dds_psel_o), .fsel_o(dds_fsel_o), .dds_reset_o(dds_reset_o), .done_o(dds_done));

    // ---------------------------------------------------------------- LEDs
    reg [HB_BITS-1:0] hb_q;
    always @(posedge clk) begin
        if (rst) hb_q <= {HB_BITS{1'b0}};
        else     hb_q <= hb_q + 1'b1;
    end
    assign led_o = {status[2:0], adc_lost, adc_err, dds_done, adc_trained, hb_q[HB_BITS-1]};
    /* verilator lint_off UNUSEDSIGNAL */
    wire unused_status = &{1'b0, status[10:3]};
    /* verilator lint_on UNUSEDSIGNAL */
endmodule
`default_nettype wire
