// fmt_dds_bank -- ROWS direct digital synthesizers, one tone per transmit row, with
// PN bi-phase modulation, time-multiplexed: one channel engine (fmt_dds_chan: phase
// ring, one amplitude product, one sine-table port) computes ROWS_PER_ENGINE = R rows,
// one per clk cycle, in the R clk cycles between two ce strobes.
//
// Each row has a PHASE_BITS phase accumulator, a tuning word, an unsigned AMP_BITS
// amplitude and an enable, written through the settings port (cfg_we_i, cfg_row_i,
// cfg_sel_i: 0 tuning word, 1 amplitude, 2 enable; rows >= ROWS and sel 3 are
// ignored; a write needs no ce and is in effect from the next ce edge on).  Reset
// defaults: row r plays FFT bin BIN_LO + r*BIN_STEP (tuning word (BIN_LO + r*BIN_STEP)
// << (PHASE_BITS - LOG2_N): exact, no truncated phase bits), full amplitude
// 2^AMP_BITS - 1, enabled.  Disabling a row zeroes its output but not its
// accumulator, so turning it on again keeps phase continuity.  All rows are
// multiplied by the shared PN sign tx_sign_i (1 = -1).
//
// Engines and tables: engine e serves rows e*R .. e*R+R-1 (slot c = row - e*R); the
// last engine's slots beyond ROWS-1 are idle.  One fmt_dds_rom2 (dual-port,
// 2^TABLE_ADDR x SINE_BITS, one RAMB18 for 1024 x 16) per pair of engines.  With
// 2^TABLE_ADDR >= 2^LOG2_N every exact-bin tone is exactly periodic in every N-sample
// window (no leakage).  Table amplitude quantization sets a worst spur of roughly -6 dB
// per SINE_BITS bit (measured by scripts/dds_purity.py); the default 16-bit table is
// below the 12-bit DAC word's own rounding.  The amplitude product (fmt_dds_chan): one
// multiplier per engine (DSP48E / ECP5 MULT18X18D, registered as XST packs it) when R > 1,
// a LUT-only Booth sum when R = 1 (no DSP48E).
//
// Output: dac_o[r*DAC_BITS +: DAC_BITS] is row r, signed, registered.  Timing: with
// sample k = k-th ce edge after reset, the word of sample k (phase = sum of the tuning
// words before it; amplitude, enable and tx_sign_i as present at edge k) is on dac_o
// after ce edge k+2, for every R; dac_o is 0 after reset until then and changes at ce
// edges only (all rows together).  The words are those of the non-multiplexed bank
// (R = 1), bit for bit.
//
// ce: R = 1: any pattern (the bank advances on ce edges only; ce = 1 under test).
// R > 1: ce must be a strobe with exactly R clk cycles from one ce edge to the next,
// from the first ce after reset on (a ce with another spacing gives wrong words;
// simulation prints an ERROR and counts it in ce_errors; ce that stops for good is not
// an error: the outputs hold, a reset restarts the bank).  Schedule
// (T_k = clk edge of ce edge k): slot c of sample k is processed at edge
// T_k + D_c, D_c = R - 1 + c (its table word was read at the edge before, see
// fmt_dds_chan): the engine takes the ring head (phase of sample k),
// tw/amp/en of slot c, and the PN sign delayed by D_c clk cycles (= tx_sign_i at
// T_k); its word is ready at T_k + D_c + 2 and goes into a staging register (the last
// slot's word is ready exactly at T_k + 2R = T_{k+2} and goes straight to dac_o), and
// all staging registers load dac_o at T_{k+2}.  The settings bus is delayed by D_c clk
// cycles for slot c, so a slot read at T_k + D_c sees exactly the writes made before
// T_k, as the non-multiplexed bank does.
// Twin: sim/fmt/dds_bank.py dds_bank_fixed.
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
    parameter ROWS_PER_ENGINE = 1,           // R: rows per channel engine (1..; R > 1 needs
                                             // ce every R clk cycles exactly, see header)
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

    localparam R      = ROWS_PER_ENGINE;
    localparam NENG   = (ROWS + R - 1) / R;     // engines
    localparam NPAIR  = (NENG + 1) / 2;         // sine tables (two engines each)
    localparam DMAX   = 2 * R - 2;              // longest slot delay D_(R-1)
    localparam SLOT_W = (R > 1) ? $clog2(R) : 1;
    localparam BUSW   = ROW_W + 2 + PHASE_BITS; // delayed settings bus: {row, sel, data}
    localparam [PHASE_BITS-1:0] TW_UNIT = {{(PHASE_BITS - 1){1'b0}}, 1'b1} << (PHASE_BITS - LOG2_N);

    // ---------------------------------------------------------------- shared control
    // settings bus and PN sign delayed by 0..DMAX clk cycles (index = delay)
    wire            we_d  [0:DMAX];
    wire [BUSW-1:0] bus_d [0:DMAX];
    wire            sg_d  [0:DMAX];
    assign we_d[0]  = cfg_we_i;
    assign bus_d[0] = {cfg_row_i, cfg_sel_i, cfg_data_i};
    assign sg_d[0]  = tx_sign_i;

    genvar j, e, c;
    generate
        for (j = 1; j <= DMAX; j = j + 1) begin : g_dly
            reg            we_q;     // reset: a write pending at reset is dropped, as at R = 1
            reg [BUSW-1:0] bus_q;
            reg            sg_q;
            always @(posedge clk) begin
                if (rst) we_q <= 1'b0;
                else     we_q <= we_d[j-1];
                bus_q <= bus_d[j-1];
                sg_q  <= sg_d[j-1];
            end
            assign we_d[j]  = we_q;
            assign bus_d[j] = bus_q;
            assign sg_d[j]  = sg_q;
        end
    endgenerate

    // per slot: the bus tap D_c = R - 1 + c
    wire [R-1:0]            slot_we;
    wire [R*ROW_W-1:0]      slot_row;
    wire [2*R-1:0]          slot_sel;
    wire [R*PHASE_BITS-1:0] slot_data;
    generate
        for (c = 0; c < R; c = c + 1) begin : g_tap
            assign slot_we[c]                            = we_d[R-1+c];
            assign slot_row[c*ROW_W +: ROW_W]            = bus_d[R-1+c][BUSW-1 -: ROW_W];
            assign slot_sel[2*c +: 2]                    = bus_d[R-1+c][PHASE_BITS +: 2];
            assign slot_data[c*PHASE_BITS +: PHASE_BITS] = bus_d[R-1+c][PHASE_BITS-1:0];
        end
    endgenerate

    // slot counter, processing enable, pipeline enable, staging strobes
    wire              pe;       // engine pipeline advance
    wire              proc;     // a slot is processed at this edge
    wire [SLOT_W-1:0] slot;     // the slot processed at this edge
    wire [R-1:0]      stg_we;   // staging write of slot c (the slot processed 2 edges ago)
    wire              sign;     // PN sign of the processed slot's sample
    generate
        if (R == 1) begin : g_r1
            assign pe     = ce;
            assign proc   = ce;
            assign slot   = 1'b0;
            assign stg_we = 1'b0;
            assign sign   = sg_d[0];
        end else begin : g_rn
            // sync = ce delayed R - 2 cycles: the edge before slot 0 is processed
            wire sync;
            if (R == 2) begin : g_s0
                assign sync = ce;
            end else begin : g_sd
                reg [R-3:0] ce_dq;    // ce_dq[i] = ce delayed i + 1 cycles
                integer n;
                always @(posedge clk) begin
                    if (rst) begin
                        ce_dq <= {(R-2){1'b0}};
                    end else begin
                        ce_dq[0] <= ce;
                        for (n = 1; n < R - 2; n = n + 1) ce_dq[n] <= ce_dq[n-1];
                    end
                end
                assign sync = ce_dq[R-3];
            end
            localparam [31:0]       SL_LAST32 = R - 1;
            localparam [SLOT_W-1:0] SL_LAST   = SL_LAST32[SLOT_W-1:0];
            reg              run_q;   // processing: from the first ce after reset on
            reg [SLOT_W-1:0] sl_q, sl1_q, sl2_q;
            always @(posedge clk) begin
                if (rst) begin
                    run_q <= 1'b0;
                    sl_q  <= {SLOT_W{1'b0}};
                    sl1_q <= {SLOT_W{1'b0}};
                    sl2_q <= {SLOT_W{1'b0}};
                end else begin
                    if (sync) run_q <= 1'b1;
                    if (sync || sl_q == SL_LAST) sl_q <= {SLOT_W{1'b0}};
                    else                       sl_q <= sl_q + 1'b1;
                    sl1_q <= sl_q;
                    sl2_q <= sl1_q;
                end
            end
            assign pe   = 1'b1;
            assign proc = run_q;
            assign slot = sl_q;
            for (c = 0; c < R; c = c + 1) begin : g_stg
                localparam [SLOT_W-1:0] SL_C = c;
                assign stg_we[c] = (sl2_q == SL_C);
            end
            // the PN sign delayed by D_slot = R - 1 + slot cycles
            reg sg_s;
            integer m;
            always @* begin
                sg_s = sg_d[R-1];
                for (m = 1; m < R; m = m + 1)
                    if (sl_q == m[SLOT_W-1:0]) sg_s = sg_d[R-1+m];
            end
            assign sign = sg_s;
        end
    endgenerate

    // ---------------------------------------------------------------- engines, tables
    // The tables are read one pipeline edge ahead of the processing edge (see
    // fmt_dds_chan); the word of sample 0 (phase 0, table word 0) comes from the cleared
    // output register at the first pe edge after reset.
    reg first_q;
    always @(posedge clk) begin
        if (rst)     first_q <= 1'b1;
        else if (pe) first_q <= 1'b0;
    end

    wire [TABLE_ADDR-1:0]       addr_w [0:2*NPAIR-1];
    wire signed [SINE_BITS-1:0] sine_w [0:2*NPAIR-1];

    generate
        for (e = 0; e < NENG; e = e + 1) begin : g_eng
            localparam ACT = (ROWS - e * R < R) ? ROWS - e * R : R;
            wire [R-1:0] we_e;
            for (c = 0; c < R; c = c + 1) begin : g_we
                // (an idle slot's row number may alias a real row when truncated: the
                // engine has no registers for idle slots, so such a write goes nowhere)
                localparam [31:0]      ROW_C32 = e * R + c;
                localparam [ROW_W-1:0] ROW_C   = ROW_C32[ROW_W-1:0];
                assign we_e[c] = slot_we[c] && (slot_row[c*ROW_W +: ROW_W] == ROW_C);
            end
            fmt_dds_chan #(
                .PHASE_BITS (PHASE_BITS),
                .TABLE_ADDR (TABLE_ADDR),
                .SINE_BITS  (SINE_BITS),
                .AMP_BITS   (AMP_BITS),
                .DAC_BITS   (DAC_BITS),
                .SLOTS      (R),
                .ACTIVE     (ACT),
                .TW_RESET   ((BIN_LO + e * R * BIN_STEP) * TW_UNIT),
                .TW_STEP    (BIN_STEP * TW_UNIT),
                .SLOT_W     (SLOT_W)
            ) u_chan (
                .clk        (clk),
                .rst        (rst),
                .pe_i       (pe),
                .proc_i     (proc),
                .slot_i     (slot),
                .sign_i     (sign),
                .cfg_we_i   (we_e),
                .cfg_sel_i  (slot_sel),
                .cfg_data_i (slot_data),
                .addr_o     (addr_w[e]),
                .sine_i     (sine_w[e]),
                .stg_we_i   (stg_we),
                .ce_i       (ce),
                .dac_o      (dac_o[e*R*DAC_BITS +: ACT*DAC_BITS])
            );
        end
        if (NENG % 2 == 1) begin : g_odd
            // the last table's second port serves no engine: read engine NENG-1's address
            assign addr_w[NENG] = addr_w[NENG-1];
        end
        for (e = 0; e < NPAIR; e = e + 1) begin : g_rom
            fmt_dds_rom2 #(
                .TABLE_ADDR (TABLE_ADDR),
                .SINE_BITS  (SINE_BITS)
            ) u_rom (
                .clk      (clk),
                .ce       (pe),
                .clr_i    (first_q),
                .addr_a_i (addr_w[2*e]),
                .addr_b_i (addr_w[2*e+1]),
                .data_a_o (sine_w[2*e]),
                .data_b_o (sine_w[2*e+1])
            );
        end
    endgenerate

    // ---------------------------------------------------------------- ce check
    // R > 1 needs ce edges exactly R clk cycles apart (after the first one after reset):
    // a ce edge that comes early or late is reported.
    // synthesis translate_off
    integer ce_errors;   // number of ce spacing errors seen (read by the testbenches)
    integer ce_gap;      // clk edges without ce since the last ce edge
    reg     ce_seen;
    initial begin
        ce_errors = 0;
        ce_gap    = 0;
        ce_seen   = 1'b0;
    end
    always @(posedge clk) begin
        if (rst) begin
            ce_seen <= 1'b0;
            ce_gap  <= 0;
        end else if (R > 1) begin
            if (ce) begin
                if (ce_seen && ce_gap != R - 1) begin
                    $display("ERROR %m at %0t: ce after %0d clk cycles, ROWS_PER_ENGINE = %0d needs exactly %0d",
                             $time, ce_gap + 1, R, R);
                    ce_errors <= ce_errors + 1;
                end
                ce_seen <= 1'b1;
                ce_gap  <= 0;
            end else begin
                ce_gap <= ce_gap + 1;
            end
        end
    end
    // synthesis translate_on

endmodule

`default_nettype wire
