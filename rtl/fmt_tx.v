// fmt_tx -- the transmit top: PN generator (fmt_pn_gen) + DDS bank (fmt_dds_bank).
//
// The PN transmit sign multiplies every row's tone (bi-phase "stir"); the delayed
// receive sign rx_sign_o leaves this block for the column despreaders ("unstir").
// Timing (sample k = k-th clock edge after reset): the DDS word of sample k is on
// dac_o after edge k+2 and carries the PN sign tx_sign_o showed after edge k-1 (PN
// sample k-1; +1 for k = 0).  So rx_sign_o lines up with the sign of the words on
// dac_o when rx_delay_i = 3 + the channel delay in samples (DAC to despreader input).
// PN off (pn_enable_i = 0) leaves the tones unmodulated; the LFSR keeps running.
//
// ce: the PN generator and the DDS bank both step on ce, so with ce every C clk cycles
// (CLK_PER_SAMPLE = C; set ROWS_PER_ENGINE = C to share one DDS engine between C rows,
// which needs exactly that ce spacing) "sample k" above is the k-th ce edge: DDS sample
// k carries PN chip floor((k - 1) / L) for chip length L samples, and chip_len_i and
// rx_delay_i are in samples whatever C is.
// Twin: sim/fmt/dds_bank.py tx_fixed.
`default_nettype none
`include "fmt_defaults.vh"

// The parameters below repeat fmt_dds_bank's (plus PN_BITS): Verilog-2001 has no way
// to inherit a parameter list, and each one is passed straight through to the bank.
module fmt_tx #(
    parameter ROWS       = `FMT_ROWS,        // number of rows (tones)
    parameter LOG2_N     = `FMT_LOG2_N,      // log2 of the FFT length N
    parameter BIN_LO     = `FMT_BIN_LO,      // FFT bin of row 0 (reset tuning)
    parameter BIN_STEP   = `FMT_BIN_STEP,    // bins between adjacent rows (reset tuning)
    parameter PHASE_BITS = `FMT_PHASE_BITS,  // phase accumulator width (<= 32)
    parameter TABLE_ADDR = 10,               // sine table address bits, >= LOG2_N
    parameter SINE_BITS  = `FMT_SINE_BITS,   // sine table word width (signed)
    parameter AMP_BITS   = `FMT_AMP_BITS,    // amplitude width (unsigned)
    parameter DAC_BITS   = `FMT_DAC_BITS,    // output word width per row (signed)
    parameter PN_BITS    = `FMT_PN_BITS,     // LFSR length (period 2^PN_BITS - 1 chips)
    parameter TAPS       = 15'h6000,         // LFSR feedback taps, PN_BITS wide (maximal)
    parameter SEED       = 1,                // LFSR reset state (non-zero)
    parameter CHIP_W     = 10,               // width of the chip-length setting
    parameter DELAY_W    = 6,                // width of the receive-delay setting
    parameter ROWS_PER_ENGINE = 1,           // rows per DDS engine (fmt_dds_bank): 1, or
                                             // CLK_PER_SAMPLE with ce every that many clk
    parameter ROW_W      = (ROWS > 1) ? $clog2(ROWS) : 1  // width of cfg_row_i
) (
    input  wire                     clk,
    input  wire                     rst,           // synchronous, active high
    input  wire                     ce,            // sample strobe of the PN and the DDS (see header)
    input  wire                     pn_enable_i,   // 0: PN off (sign +1)
    input  wire [CHIP_W-1:0]        chip_len_i,    // samples per chip (0 = 1)
    input  wire [DELAY_W-1:0]       rx_delay_i,    // receive-sign delay in samples
    input  wire                     cfg_we_i,      // DDS settings write strobe
    input  wire [ROW_W-1:0]         cfg_row_i,     // row of the write
    input  wire [1:0]               cfg_sel_i,     // 0 tuning word, 1 amplitude, 2 enable
    input  wire [PHASE_BITS-1:0]    cfg_data_i,    // value, LSB-aligned
    output wire [ROWS*DAC_BITS-1:0] dac_o,         // row r at [r*DAC_BITS +: DAC_BITS], signed
    output wire                     tx_sign_o,     // PN transmit sign (1 = -1), registered
    output wire                     rx_sign_o,     // PN receive sign, delayed by rx_delay_i
    output wire                     chip_start_o   // first sample of each chip
);

    fmt_pn_gen #(
        .PN_BITS (PN_BITS),
        .TAPS    (TAPS),
        .SEED    (SEED),
        .CHIP_W  (CHIP_W),
        .DELAY_W (DELAY_W)
    ) u_pn (
        .clk          (clk),
        .rst          (rst),
        .ce           (ce),
        .enable_i     (pn_enable_i),
        .chip_len_i   (chip_len_i),
        .rx_delay_i   (rx_delay_i),
        .tx_sign_o    (tx_sign_o),
        .rx_sign_o    (rx_sign_o),
        .chip_start_o (chip_start_o)
    );

    fmt_dds_bank #(
        .ROWS       (ROWS),
        .LOG2_N     (LOG2_N),
        .BIN_LO     (BIN_LO),
        .BIN_STEP   (BIN_STEP),
        .PHASE_BITS (PHASE_BITS),
        .TABLE_ADDR (TABLE_ADDR),
        .SINE_BITS  (SINE_BITS),
        .AMP_BITS   (AMP_BITS),
        .DAC_BITS   (DAC_BITS),
        .ROWS_PER_ENGINE (ROWS_PER_ENGINE),
        .ROW_W      (ROW_W)
    ) u_dds (
        .clk        (clk),
        .rst        (rst),
        .ce         (ce),
        .cfg_we_i   (cfg_we_i),
        .cfg_row_i  (cfg_row_i),
        .cfg_sel_i  (cfg_sel_i),
        .cfg_data_i (cfg_data_i),
        .tx_sign_i  (tx_sign_o),
        .dac_o      (dac_o)
    );

endmodule

`default_nettype wire
