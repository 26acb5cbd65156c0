// fpga -- XC5VSX95T (FF1136) board top of the FMT controller: the vendor primitives
// only (this is the one file of the project that instantiates Virtex-5 primitives);
// everything else is fpga_core.v (portable, simulated in tb/fpga_xc5v).
//
// Clocking: the ADCs are clocked at fs = 41.667 MHz by the analog board's oscillator
// (fanned out to the DDS chips' MCLK as well); ADC chip 0's LVDS bit clock LCLK
// (6 x fs = 250 MHz, data at 500 Mb/s DDR) -> IBUFDS -> PLL_BASE (VCO 1000 MHz):
//   CLKOUT0 250 MHz  clk_bit  ISERDES CLK (BUFG)
//   CLKOUT1 125 MHz  clk      fpga_core / fmt_core, ISERDES CLKDIV (BUFG): 3 x fs
//   CLKOUT2 200 MHz  clk_ref  IDELAYCTRL reference (BUFG)
// so clk and the ISERDES words are one domain, phase-locked to the ADCs.  The other
// chips' LCLK pairs are received (IBUFDS) and left unused (the frame lanes align them).
// Each data lane and each chip's frame clock (ADCLK): IBUFDS (DIFF_TERM) -> IODELAY
// (VARIABLE, stepped by fpga_core's training) -> ISERDES_NODELAY (NETWORKING, DDR,
// width SER_W = 4 at 3 clk per sample): SER_W bits per clk, {Q4, Q3, Q2, Q1} taken as earliest-first (the first
// bit received on the highest Q used, as understood from UG190; a wrong order shows at
// bring-up as a training that never finds the sync pattern: LED 3).
// Reset: the PLL's LOCKED and the active-low button, through a 4-flop synchroniser in
// clk (rst held until the PLL has locked and the IDELAYCTRL is ready).
// No model twin; not simulated (the primitives' models are not part of this repository):
// tb/fpga_xc5v runs fpga_core with behavioural lane models.
`default_nettype none
`include "fmt_defaults.vh"

// The parameters are fmt_core's (fmt_core.core's generics reach this top through the ISE
// project) and are passed down unchanged.
module fpga #(
    parameter ROWS           = `FMT_ROWS,         // transmit rows = DDS chips
    parameter COLS           = `FMT_COLS,         // receive columns = ADC data lanes (8 per chip)
    parameter LOG2_N         = `FMT_LOG2_N,       // FFT size N = 2^LOG2_N
    parameter BIN_LO         = `FMT_BIN_LO,       // FFT bin of row 0
    parameter BIN_STEP       = `FMT_BIN_STEP,     // bins between rows
    parameter ADC_BITS       = `FMT_ADC_BITS,     // ADC word width (12: ADS5272)
    parameter DAC_BITS       = `FMT_DAC_BITS,     // DAC port word width
    parameter PHASE_BITS     = `FMT_PHASE_BITS,   // DDS phase accumulator width
    parameter SINE_BITS      = `FMT_SINE_BITS,    // DDS sine table width
    parameter AMP_BITS       = `FMT_AMP_BITS,     // DDS amplitude width
    parameter PN_BITS        = `FMT_PN_BITS,      // PN LFSR length
    parameter HM_W           = `FMT_HM_W,         // heat-map cell width
    parameter MAX_TOUCHES    = `FMT_MAX_TOUCHES,  // contact limit
    parameter CLK_PER_SAMPLE = 3,                 // clk per sample: 3 (ISERDES width 4) or 2 (width 6)
    parameter M_MAX          = 255,               // largest windows per frame
    parameter EV_DEPTH       = 2048,              // event FIFO entries
    parameter BLOBS          = 1,                 // blob detector built
    parameter UART_DIV       = 1085,              // clk per UART bit (125 MHz: 115200 baud)
    parameter UART_TIMEOUT   = 40,                // control-port timeout, bit times
    parameter CHIPS          = (COLS + 7) / 8     // ADS5272-class chips
) (
    input  wire                 rst_n_i,        // push button, active low
    // ADS5272-class ADCs
    input  wire [CHIPS-1:0]     adc_lclk_p_i,   // bit clocks (chip 0's is the clock source)
    input  wire [CHIPS-1:0]     adc_lclk_n_i,
    input  wire [CHIPS-1:0]     adc_fclk_p_i,   // frame clocks (ADCLK), 1 x fs
    input  wire [CHIPS-1:0]     adc_fclk_n_i,
    input  wire [COLS-1:0]      adc_d_p_i,      // data lanes, column c
    input  wire [COLS-1:0]      adc_d_n_i,
    output wire                 adc_sclk_o,     // serial control port (shared)
    output wire                 adc_sdata_o,
    output wire                 adc_cs_n_o,
    // AD9834-class DDS chips
    output wire                 dds_sclk_o,
    output wire [ROWS-1:0]      dds_sdata_o,
    output wire                 dds_fsync_n_o,
    output wire                 dds_psel_o,
    output wire                 dds_fsel_o,
    output wire                 dds_reset_o,
    // host
    input  wire                 uart_rx_i,
    output wire                 uart_tx_o,
    input  wire                 trig_i,
    output wire [7:0]           led_o
);
    localparam NL    = COLS + CHIPS;
    localparam SER_W = ADC_BITS / CLK_PER_SAMPLE;   // ISERDES width; CLKDIV = 6 x fs / (SER_W / 2) = clk

    // ---------------------------------------------------------------- clocks
    wire lclk_ibuf, pll_fb, pll_locked, clk_bit_pll, clk_pll, clk_ref_pll;
    wire clk_bit, clk, clk_ref;
    IBUFDS #(.DIFF_TERM("TRUE"), .IOSTANDARD("LVDS_25")) u_lclk_buf (
        .I(adc_lclk_p_i[0]), .IB(adc_lclk_n_i[0]), .O(lclk_ibuf));
    PLL_BASE #(
        .BANDWIDTH("OPTIMIZED"), .CLKIN_PERIOD(4.0), .DIVCLK_DIVIDE(1),
        .CLKFBOUT_MULT(4), .CLKFBOUT_PHASE(0.0),
        .CLKOUT0_DIVIDE(4), .CLKOUT0_PHASE(0.0), .CLKOUT0_DUTY_CYCLE(0.5),
        .CLKOUT1_DIVIDE(2 * SER_W), .CLKOUT1_PHASE(0.0), .CLKOUT1_DUTY_CYCLE(0.5),
        .CLKOUT2_DIVIDE(5), .CLKOUT2_PHASE(0.0), .CLKOUT2_DUTY_CYCLE(0.5),
        .COMPENSATION("SYSTEM_SYNCHRONOUS"), .REF_JITTER(0.100)
    ) u_pll (
        .CLKIN(lclk_ibuf), .CLKFBIN(pll_fb), .CLKFBOUT(pll_fb), .RST(1'b0),
        .CLKOUT0(clk_bit_pll), .CLKOUT1(clk_pll), .CLKOUT2(clk_ref_pll),
        .CLKOUT3(), .CLKOUT4(), .CLKOUT5(), .LOCKED(pll_locked));
    BUFG u_bufg_bit (.I(clk_bit_pll), .O(clk_bit));
    BUFG u_bufg_clk (.I(clk_pll),     .O(clk));
    BUFG u_bufg_ref (.I(clk_ref_pll), .O(clk_ref));

    wire idelay_rdy;
    IDELAYCTRL u_idelayctrl (.REFCLK(clk_ref), .RST(!pll_locked), .RDY(idelay_rdy));

    // ---------------------------------------------------------------- reset
    (* ASYNC_REG = "TRUE" *) reg [3:0] rst_sync_q = 4'hF;
    always @(posedge clk or negedge pll_locked) begin
        if (!pll_locked) rst_sync_q <= 4'hF;
        else             rst_sync_q <= {rst_sync_q[2:0], !(rst_n_i && idelay_rdy)};
    end
    wire rst = rst_sync_q[3];

    // ---------------------------------------------------------------- ADC lanes
    wire [NL-1:0]   lane_p = {adc_fclk_p_i, adc_d_p_i};
    wire [NL-1:0]   lane_n = {adc_fclk_n_i, adc_d_n_i};
    wire [NL*SER_W-1:0] lane_bits;
    wire            dly_rst, dly_inc;
    wire [NL-1:0]   dly_ce;
    genvar g;
    generate
        for (g = 0; g < NL; g = g + 1) begin : g_lane
            wire d_ibuf, d_dly, q1, q2, q3, q4, q5, q6;
            IBUFDS #(.DIFF_TERM("TRUE"), .IOSTANDARD("LVDS_25")) u_ibuf (
                .I(lane_p[g]), .IB(lane_n[g]), .O(d_ibuf));
            IODELAY #(
                .IDELAY_TYPE("VARIABLE"), .IDELAY_VALUE(0), .DELAY_SRC("I"),
                .HIGH_PERFORMANCE_MODE("TRUE"), .REFCLK_FREQUENCY(200.0), .SIGNAL_PATTERN("DATA")
            ) u_dly (
                .IDATAIN(d_ibuf), .DATAOUT(d_dly), .C(clk), .CE(dly_ce[g]), .INC(dly_inc),
                .RST(dly_rst), .ODATAIN(1'b0), .DATAIN(1'b0), .T(1'b1));
            ISERDES_NODELAY #(
                .BITSLIP_ENABLE("FALSE"), .DATA_RATE("DDR"), .DATA_WIDTH(SER_W),
                .INTERFACE_TYPE("NETWORKING"), .NUM_CE(1), .SERDES_MODE("MASTER")
            ) u_iserdes (
                .D(d_dly), .CLK(clk_bit), .CLKB(!clk_bit), .CLKDIV(clk), .OCLK(1'b0),
                .CE1(1'b1), .CE2(1'b1), .RST(rst), .BITSLIP(1'b0),
                .SHIFTIN1(1'b0), .SHIFTIN2(1'b0), .SHIFTOUT1(), .SHIFTOUT2(),
                .Q1(q1), .Q2(q2), .Q3(q3), .Q4(q4), .Q5(q5), .Q6(q6));
            // earliest bit on the highest Q used
            wire [5:0] q_all = {q6, q5, q4, q3, q2, q1};
            assign lane_bits[g*SER_W +: SER_W] = q_all[SER_W-1:0];
        end
        for (g = 1; g < CHIPS; g = g + 1) begin : g_lclk
            wire unused_lclk;     // received for termination only
            IBUFDS #(.DIFF_TERM("TRUE"), .IOSTANDARD("LVDS_25")) u_ibuf (
                .I(adc_lclk_p_i[g]), .IB(adc_lclk_n_i[g]), .O(unused_lclk));
        end
    endgenerate

    // ---------------------------------------------------------------- core
    fpga_core #(
        .ROWS(ROWS), .COLS(COLS), .LOG2_N(LOG2_N), .BIN_LO(BIN_LO), .BIN_STEP(BIN_STEP),
        .HM_W(HM_W), .MAX_TOUCHES(MAX_TOUCHES), .ADC_BITS(ADC_BITS), .DAC_BITS(DAC_BITS),
        .PHASE_BITS(PHASE_BITS), .SINE_BITS(SINE_BITS), .AMP_BITS(AMP_BITS), .PN_BITS(PN_BITS),
        .CLK_PER_SAMPLE(CLK_PER_SAMPLE), .M_MAX(M_MAX), .CHIPS(CHIPS), .SER_W(SER_W),
        .UART_DIV(UART_DIV), .UART_TIMEOUT(UART_TIMEOUT), .EV_DEPTH(EV_DEPTH), .BLOBS(BLOBS)
    ) u_core (
        .clk(clk), .rst(rst),
        .adc_data_bits_i(lane_bits[COLS*SER_W-1:0]), .adc_frame_bits_i(lane_bits[NL*SER_W-1:COLS*SER_W]),
        .adc_dly_rst_o(dly_rst), .adc_dly_ce_o(dly_ce), .adc_dly_inc_o(dly_inc),
        .adc_sclk_o(adc_sclk_o), .adc_sdata_o(adc_sdata_o), .adc_cs_n_o(adc_cs_n_o),
        .dds_sclk_o(dds_sclk_o), .dds_sdata_o(dds_sdata_o), .dds_fsync_n_o(dds_fsync_n_o),
        .dds_psel_o(dds_psel_o), .dds_fsel_o(dds_fsel_o), .dds_reset_o(dds_reset_o),
        .dac_o(), .dac_ce_o(),
        .uart_rx_i(uart_rx_i), .uart_tx_o(uart_tx_o), .trig_i(trig_i), .led_o(led_o));
endmodule
`default_nettype wire
