// fmt_dds_bank -- ROWS direct digital synthesizers, one tone per transmit row, with
// PN bi-phase modulation.
//
// Each row (fmt_dds_chan) has a PHASE_BITS phase accumulator, a tuning word, an
// unsigned AMP_BITS amplitude and an enable, written through the settings port
// (cfg_we_i, cfg_row_i, cfg_sel_i: 0 tuning word, 1 amplitude, 2 enable; rows >= ROWS
// and sel 3 are ignored).  Reset defaults: row r plays FFT bin BIN_LO + r*BIN_STEP
// (tuning word (BIN_LO + r*BIN_STEP) << (PHASE_BITS - LOG2_N): exact, no truncated
// phase bits), full amplitude 2^AMP_BITS - 1, enabled.  Disabling a row zeroes its
// output but not its accumulator, so turning it on again keeps phase continuity.
// All rows are multiplied by the shared PN sign tx_sign_i (1 = -1).
//
// Sine tables: one fmt_dds_rom2 (dual-port, 2^TABLE_ADDR x SINE_BITS, one RAMB18 for
// 1024 x 16) per pair of rows.  With 2^TABLE_ADDR >= 2^LOG2_N every exact-bin tone is
// exactly periodic in every N-sample window (no leakage).  Table amplitude
// quantization sets a worst spur of roughly -6 dB per SINE_BITS bit (measured by
// scripts/dds_purity.py); the default 16-bit table is below the 12-bit DAC word's own
// rounding.  No DSP48E: the amplitude product is a LUT shift-add (fmt_dds_chan).
//
// Output: dac_o[r*DAC_BITS +: DAC_BITS] is row r, signed, registered.  Timing: with
// sample k = k-th ce edge after reset, the word of sample k (phase = sum of the tuning
// words before it; amplitude, enable and tx_sign_i as present at edge k) is on dac_o
// after ce edge k+2; dac_o is 0 after reset until then.  Settings writes need no ce.
// Twin: sim/fmt/dds.py dds_bank_fixed.
`default_nettype none
`include "fmt_defaults.vh"

module fmt_dds_bank #(
    parameter ROWS       = `FMT_ROWS,        // number of rows (tones)
    parameter LOG2_N     = `FMT_LOG2_N,      // log2 of the FFT length N
    parameter BIN_LO     = `FMT_BIN_LO,      // FFT bin of row 0 (reset tuning)
    parameter BIN_STEP   = `FMT_BIN_STEP,    // bins between adjacent rows (reset tuning)
    parameter PHASE_BITS = `FMT_PHASE_BITS,  // phase accumulator width (<= 32)
    parameter TABLE_ADDR = 10,               // sine table address bits, >= LOG2_N
    parameter SINE_BITS  = `FMT_SINE_BITS,   // sine table word width (signed)
    parameter AMP_BITS   = `FMT_AMP_BITS,    // amplitude width (unsigned)
    parameter DAC_BITS   = `FMT_DAC_BITS,    // output word width per row (signed)
    parameter ROW_W      = (ROWS > 1) ? $clog2(ROWS) : 1  // width of cfg_row_i
) (
    input  wire                        clk,
    input  wire                        rst,         // synchronous, active high
    input  wire                        ce,          // sample strobe
    input  wire                        cfg_we_i,    // settings write strobe
    input  wire [ROW_W-1:0]            cfg_row_i,   // row of the write
    input  wire [1:0]                  cfg_sel_i,   // 0 tuning word, 1 amplitude, 2 enable
    input  wire [PHASE_BITS-1:0]       cfg_data_i,  // value, LSB-aligned
    input  wire                        tx_sign_i,   // PN transmit sign, 1 = multiply by -1
    output wire [ROWS*DAC_BITS-1:0]    dac_o        // row r at [r*DAC_BITS +: DAC_BITS], signed
);

    localparam NPAIR = (ROWS + 1) / 2;

    wire [TABLE_ADDR-1:0]       addr_w [0:2*NPAIR-1];
    wire signed [SINE_BITS-1:0] sine_w [0:2*NPAIR-1];

    genvar r, p;
    generate
        for (r = 0; r < ROWS; r = r + 1) begin : g_row
            fmt_dds_chan #(
                .PHASE_BITS (PHASE_BITS),
                .TABLE_ADDR (TABLE_ADDR),
                .SINE_BITS  (SINE_BITS),
                .AMP_BITS   (AMP_BITS),
                .DAC_BITS   (DAC_BITS),
                .TW_RESET   ((BIN_LO + r * BIN_STEP) << (PHASE_BITS - LOG2_N))
            ) u_chan (
                .clk        (clk),
                .rst        (rst),
                .ce         (ce),
                .cfg_we_i   (cfg_we_i && (cfg_row_i == r)),
                .cfg_sel_i  (cfg_sel_i),
                .cfg_data_i (cfg_data_i),
                .tx_sign_i  (tx_sign_i),
                .addr_o     (addr_w[r]),
                .sine_i     (sine_w[r]),
                .dac_o      (dac_o[r*DAC_BITS +: DAC_BITS])
            );
        end
        if (ROWS % 2 == 1) begin : g_odd
            // the last table's second port serves no row: read row ROWS-1's address
            assign addr_w[ROWS] = addr_w[ROWS-1];
        end
        for (p = 0; p < NPAIR; p = p + 1) begin : g_rom
            fmt_dds_rom2 #(
                .TABLE_ADDR (TABLE_ADDR),
                .SINE_BITS  (SINE_BITS)
            ) u_rom (
                .clk      (clk),
                .ce       (ce),
                .addr_a_i (addr_w[2*p]),
                .addr_b_i (addr_w[2*p+1]),
                .data_a_o (sine_w[2*p]),
                .data_b_o (sine_w[2*p+1])
            );
        end
    endgenerate

endmodule

`default_nettype wire
