// fmt_adc_deser -- portable receive side of ADS5272-class ADCs (8 channels per chip,
// ADC_BITS-bit words, one serial LVDS lane per channel at ADC_BITS x fs, DDR bit clock
// ADC_BITS/2 x fs, frame clock 1 x fs): lane training, word alignment and the words of
// all COLS columns, one set per WPC clk.
//
// Input: every lane (COLS data lanes, CHIPS frame-clock lanes) as the board top's
// ISERDES gives it: SER_W bits per clk, bit [SER_W-1] the earliest.  With SER_W = 4
// (ISERDES DDR width 4) its CLKDIV is 6 x fs / 2 = 3 x fs = clk: the board top clocks the
// ISERDES with the bit clock and clk from one PLL locked to the ADC's bit clock, so
// the words are already in the clk domain (no FIFO).  WPC = ADC_BITS / SER_W clk per word
// must equal fmt_core's CLK_PER_SAMPLE.
//
// Training (after rst and on train_i), over the ADCs' serial control port (fmt_spi_wr,
// one SCLK / SDATA / CS shared by all chips; the three register words are parameters):
//  1. TP_DESKEW (0101... on every data lane); per-lane delay scan: all IODELAYs reset
//     (dly_rst_o), then for each of TAPS taps: DWELL word periods, the tap is good when
//     the lane's last ADC_BITS bits are equal in every period and not constant (the
//     deskew pattern on data lanes, the frame clock on frame lanes); one tap up for all
//     lanes (dly_ce_o, dly_inc_o).  Each lane keeps its longest run of good taps; then
//     the delays are reset and each lane is stepped to the middle of its run (a lane whose
//     run is shorter than MIN_EYE taps restarts the training, err_o).
//  2. TP_SYNC (SYNC_WORD on every data lane, the frame clock's own shape): each lane's
//     word boundary b (0 .. ADC_BITS-1 bits before the newest bit of a period) is found
//     and must hold for LOCK periods (else restart).  A data lane takes the word ending
//     at e = B + d, B = chip 0's frame-lane boundary b_f, + ADC_BITS if b_f < ADC_BITS/2 (one reference for
//     all chips: every lane's word of one sample clock edge is taken in the same period)
//     and d = b - b_f wrapped to -ADC_BITS/2 .. ADC_BITS/2-1: every lane may be skewed by
//     up to half a word against chip 0's frame clock (whole bits; the delay scan removes
//     the sub-bit part).
//  3. TP_NORMAL; trained_o rises.  While trained, every frame lane must keep SYNC_WORD at
//     its boundary (else lost_o, sticky until the next training).
// Output: adc_o changes one clk after each word period's strobe (word_stb_o) and holds for
// WPC clk; bit order MSB first on the lane (LSB_FIRST = 1 reverses).
// Storage: (COLS + CHIPS) x (2 x ADC_BITS)-bit lane histories, per-lane run counters,
// COLS x 2 x ADC_BITS word registers (previous word, output); per data lane a 12:1 word
// select (its boundary) and a 2:1 (latest or previous word).  Latency: a word's last bit -> adc_o 2 .. 2 + WPC clk plus
// its lane offset.  No model twin: tb/fpga_xc5v checks it against the ADC's serial model.
`default_nettype none

module fmt_adc_deser #(
    parameter COLS        = 6,              // data lanes (receive columns)
    parameter CH_PER_CHIP = 8,              // channels (data lanes) per ADC chip
    parameter CHIPS       = (COLS + CH_PER_CHIP - 1) / CH_PER_CHIP,  // ADC chips = frame lanes
    parameter ADC_BITS    = 12,             // ADC word width
    parameter SER_W       = 4,              // bits per lane per clk (ISERDES width)
    parameter TAPS        = 64,             // IODELAY taps
    parameter DWELL       = 16,             // word periods checked per tap
    parameter MIN_EYE     = 4,              // shortest accepted run of good taps
    parameter LOCK        = 16,             // word periods the sync boundary must hold
    parameter SETTLE      = 64,             // word periods waited after a register write
    parameter SPI_DIV     = 4,              // clk per SCLK half period (125 MHz: 15.6 MHz SCLK)
    parameter [15:0] TP_DESKEW = 16'h0000,  // ADC register word: deskew test pattern on (board README)
    parameter [15:0] TP_SYNC   = 16'h0000,  // ADC register word: sync test pattern on
    parameter [15:0] TP_NORMAL = 16'h0000,  // ADC register word: test patterns off
    parameter [ADC_BITS-1:0] SYNC_WORD = 12'hFC0,  // sync pattern / frame-clock shape, first bit at MSB
    parameter LSB_FIRST   = 0               // 1: the lanes send the LSB first
) (
    input  wire                      clk,           // 3 x fs, CLKDIV of the ISERDES
    input  wire                      rst,           // synchronous, active high
    input  wire                      train_i,       // restart the training
    input  wire [COLS*SER_W-1:0]     data_bits_i,   // lane c at [c*SER_W +: SER_W]
    input  wire [CHIPS*SER_W-1:0]    frame_bits_i,  // frame lane of chip k at [k*SER_W +: SER_W]
    output wire [COLS*ADC_BITS-1:0]  adc_o,         // column c word at [c*ADC_BITS +: ADC_BITS]
    output wire                      word_stb_o,    // a word period ends (adc_o changes next clk)
    output wire                      trained_o,     // training done, adc_o carries samples
    output wire                      err_o,         // a training was restarted (sticky)
    output wire                      lost_o,        // a frame lane lost its boundary (sticky)
    output wire                      dly_rst_o,     // all IODELAYs to tap 0
    output wire [COLS+CHIPS-1:0]     dly_ce_o,      // lane's IODELAY steps (data lanes, then frame lanes)
    output wire                      dly_inc_o,     // step direction: 1 = up
    output wire                      spi_sclk_o,    // ADC serial control port
    output wire                      spi_sdata_o,
    output wire                      spi_cs_n_o
);
    localparam NL    = COLS + CHIPS;            // lanes
    localparam WPC   = ADC_BITS / SER_W;        // clk per word
    localparam HW    = 2 * ADC_BITS;            // history bits per lane
    localparam HALF  = ADC_BITS / 2;
    localparam WPC_W = (WPC > 1) ? $clog2(WPC) : 1;
    localparam TAP_W = $clog2(TAPS + 1);
    localparam B_W   = $clog2(ADC_BITS);
    localparam E_W   = $clog2(HW);
    localparam CNT_W = 16;
    localparam [WPC_W-1:0] WPC_LAST = WPC[WPC_W-1:0] - 1'b1;
    localparam [TAP_W-1:0] TAPS_T   = TAPS[TAP_W-1:0];
    localparam [TAP_W-1:0] MIN_T    = MIN_EYE[TAP_W-1:0];
    localparam [CNT_W-1:0] DWELL_C  = DWELL[CNT_W-1:0];
    localparam [CNT_W-1:0] LOCK_C   = LOCK[CNT_W-1:0];
    localparam [CNT_W-1:0] SETTLE_C = SETTLE[CNT_W-1:0];

    // FSM states
    localparam [3:0] S_SPI1 = 4'd0, S_SET1 = 4'd1, S_SCAN = 4'd2, S_STEP = 4'd3,
                     S_CENT = 4'd4, S_SPI2 = 4'd5, S_SET2 = 4'd6, S_FIND = 4'd7,
                     S_LOCK = 4'd8, S_SPI3 = 4'd9, S_SET3 = 4'd10, S_RUN = 4'd11,
                     S_WAIT = 4'd12;

    // ---------------------------------------------------------------- lane histories
    reg  [WPC_W-1:0] ph_q;
    wire             per = (ph_q == {WPC_W{1'b0}});   // the histories end on a word period
    reg  [HW-1:0]    hist_q [0:NL-1];
    integer lh, lc, bc, le, ls, lf, lo, bo, lq;   // one loop variable per process
    always @(posedge clk) begin
        if (rst || ph_q == WPC_LAST) ph_q <= {WPC_W{1'b0}};
        else                        ph_q <= ph_q + 1'b1;
        for (lh = 0; lh < NL; lh = lh + 1)
            hist_q[lh] <= {hist_q[lh][HW-SER_W-1:0],
                          (lh < COLS) ? data_bits_i[lh*SER_W +: SER_W] : frame_bits_i[(lh-COLS)*SER_W +: SER_W]};
    end

    // per-lane checks of the current period (combinational)
    reg  [ADC_BITS-1:0] prev_q [0:NL-1];
    reg  [NL-1:0]       stable, fnd;
    reg  [B_W-1:0]      bnew [0:NL-1];
    reg  [B_W-1:0]      b_q  [0:NL-1];
    reg  [NL-1:0]       hold;
    always @(*) begin
        for (lc = 0; lc < NL; lc = lc + 1) begin
            stable[lc] = (hist_q[lc][ADC_BITS-1:0] == prev_q[lc]) &&
                        (hist_q[lc][ADC_BITS-1:0] != {ADC_BITS{1'b0}}) &&
                        (hist_q[lc][ADC_BITS-1:0] != {ADC_BITS{1'b1}});
            fnd[lc]  = 1'b0;
            bnew[lc] = {B_W{1'b0}};
            for (bc = ADC_BITS - 1; bc >= 0; bc = bc - 1)
                if (hist_q[lc][bc +: ADC_BITS] == SYNC_WORD) begin
                    fnd[lc]  = 1'b1;
                    bnew[lc] = bc[B_W-1:0];
                end
            hold[lc] = (hist_q[lc][{{(E_W-B_W){1'b0}}, b_q[lc]} +: ADC_BITS] == SYNC_WORD);
        end
    end

    // ---------------------------------------------------------------- training FSM
    reg  [3:0]       st_q, nxt_q;                 // state, state after S_WAIT
    reg  [CNT_W-1:0] cnt_q;                       // word periods in a state
    reg  [TAP_W-1:0] tap_q;                       // scan tap / centring step
    reg              spi_start_q;
    reg  [15:0]      spi_word_q;
    wire             spi_busy;
    reg              trained_q, err_q, lost_q, dly_rst_q, dly_inc_q;
    reg  [NL-1:0]    dly_ce_q, good_q;
    reg              skip_q;                      // first period after a tap step: not judged
    reg  [TAP_W-1:0] cur_s_q [0:NL-1];
    reg  [TAP_W-1:0] cur_n_q [0:NL-1];
    reg  [TAP_W-1:0] best_s_q [0:NL-1];
    reg  [TAP_W-1:0] best_n_q [0:NL-1];
    reg  [TAP_W-1:0] cent_q  [0:NL-1];
    reg  [COLS-1:0]  sp_q;                        // data lane gives its previous word
    reg              eye_ok;
    always @(*) begin
        eye_ok = 1'b1;
        for (le = 0; le < NL; le = le + 1)
            if (best_n_q[le] < MIN_T) eye_ok = 1'b0;
    end

    // which word a data lane gives: its latest complete word (ending b bits before the
    // newest) or the one before (ending b + ADC_BITS bits before): the one that ends at
    // e = B + d, B = b_f (+ ADC_BITS when b_f < ADC_BITS/2) the reference boundary in
    // HALF .. HALF + ADC_BITS - 1, so e is in 0 .. 2 ADC_BITS - 2: the previous word when
    // e >= ADC_BITS
    reg  [COLS-1:0]  sp_new;
    reg  [B_W:0]     dd;
    reg  [B_W+1:0]   ee;
    always @(*) begin
        dd = {(B_W+1){1'b0}};
        ee = {(B_W+2){1'b0}};
        for (ls = 0; ls < COLS; ls = ls + 1) begin
            // d = b - b_f mod ADC_BITS, in 0 .. ADC_BITS-1 (d >= HALF stands for d - ADC_BITS)
            if (b_q[ls] >= b_q[COLS])
                dd = {1'b0, b_q[ls]} - {1'b0, b_q[COLS]};
            else
                dd = {1'b0, b_q[ls]} + ADC_BITS[B_W:0] - {1'b0, b_q[COLS]};
            ee = {2'b00, b_q[COLS]} + {1'b0, dd};
            if ({1'b0, b_q[COLS]} < HALF[B_W:0]) ee = ee + ADC_BITS[B_W+1:0];
            if (dd >= HALF[B_W:0])               ee = ee - ADC_BITS[B_W+1:0];
            sp_new[ls] = (ee >= ADC_BITS[B_W+1:0]);
        end
    end

    always @(posedge clk) begin
        spi_start_q <= 1'b0;
        dly_rst_q   <= 1'b0;
        dly_ce_q    <= {NL{1'b0}};
        if (rst || train_i) begin
            st_q      <= S_SPI1;
            nxt_q     <= S_SET1;
            cnt_q     <= {CNT_W{1'b0}};
            tap_q     <= {TAP_W{1'b0}};
            trained_q <= 1'b0;
            lost_q    <= 1'b0;
            dly_inc_q <= 1'b1;
            skip_q    <= 1'b1;
            good_q    <= {NL{1'b1}};
            if (rst) err_q <= 1'b0;
            sp_q      <= {COLS{1'b0}};
            spi_word_q <= TP_DESKEW;
            for (lf = 0; lf < NL; lf = lf + 1) begin
                prev_q[lf]   <= {ADC_BITS{1'b0}};
                b_q[lf]      <= {B_W{1'b0}};
                cur_s_q[lf]  <= {TAP_W{1'b0}};
                cur_n_q[lf]  <= {TAP_W{1'b0}};
                best_s_q[lf] <= {TAP_W{1'b0}};
                best_n_q[lf] <= {TAP_W{1'b0}};
                cent_q[lf]   <= {TAP_W{1'b0}};
            end
        end else begin
            if (per)
                for (lf = 0; lf < NL; lf = lf + 1) prev_q[lf] <= hist_q[lf][ADC_BITS-1:0];
            case (st_q)
                // one register write, then wait until the transfer ends
                S_SPI1, S_SPI2, S_SPI3: begin
                    spi_start_q <= 1'b1;
                    st_q        <= S_WAIT;
                    nxt_q       <= (st_q == S_SPI1) ? S_SET1 : (st_q == S_SPI2) ? S_SET2 : S_SET3;
                    cnt_q       <= {CNT_W{1'b0}};
                end
                S_WAIT: if (!spi_start_q && !spi_busy) st_q <= nxt_q;
                // settle after a pattern change (SET1 also resets the delays)
                S_SET1, S_SET2, S_SET3: begin
                    if (cnt_q == {CNT_W{1'b0}} && st_q == S_SET1) dly_rst_q <= 1'b1;
                    if (per) cnt_q <= cnt_q + 1'b1;
                    if (per && cnt_q == SETTLE_C) begin
                        cnt_q  <= {CNT_W{1'b0}};
                        skip_q <= 1'b1;
                        good_q <= {NL{1'b1}};
                        tap_q  <= {TAP_W{1'b0}};
                        st_q   <= (st_q == S_SET1) ? S_SCAN : (st_q == S_SET2) ? S_FIND : S_RUN;
                        if (st_q == S_SET3) trained_q <= 1'b1;
                    end
                end
                // judge DWELL periods at this tap, then record the run and step up
                S_SCAN: if (per) begin
                    skip_q <= 1'b0;
                    if (!skip_q) begin
                        good_q <= good_q & stable;
                        cnt_q  <= cnt_q + 1'b1;
                        if (cnt_q == DWELL_C - 1'b1) begin
                            for (lf = 0; lf < NL; lf = lf + 1) begin
                                if (good_q[lf] && stable[lf]) begin
                                    if (cur_n_q[lf] == {TAP_W{1'b0}}) cur_s_q[lf] <= tap_q;
                                    cur_n_q[lf] <= cur_n_q[lf] + 1'b1;
                                    if (cur_n_q[lf] + 1'b1 > best_n_q[lf]) begin
                                        best_n_q[lf] <= cur_n_q[lf] + 1'b1;
                                        best_s_q[lf] <= (cur_n_q[lf] == {TAP_W{1'b0}}) ? tap_q : cur_s_q[lf];
                                    end
                                end else begin
                                    cur_n_q[lf] <= {TAP_W{1'b0}};
                                end
                            end
                            st_q <= S_STEP;
                        end
                    end
                end
                S_STEP: begin
                    dly_ce_q <= {NL{1'b1}};
                    cnt_q    <= {CNT_W{1'b0}};
                    good_q   <= {NL{1'b1}};
                    skip_q   <= 1'b1;
                    tap_q    <= tap_q + 1'b1;
                    if (tap_q == TAPS_T - 1'b1) begin
                        st_q <= S_CENT;
                        for (lf = 0; lf < NL; lf = lf + 1)
                            cent_q[lf] <= best_s_q[lf] + {1'b0, best_n_q[lf][TAP_W-1:1]};
                    end else begin
                        st_q <= S_SCAN;
                    end
                end
                // delays to 0, then each lane up to the middle of its eye
                S_CENT: begin
                    if (tap_q == TAPS_T) begin
                        dly_rst_q <= 1'b1;
                        tap_q     <= {TAP_W{1'b0}};
                        if (!eye_ok) begin
                            err_q <= 1'b1;
                            st_q  <= S_SPI1;
                        end
                    end else begin
                        for (lf = 0; lf < NL; lf = lf + 1) dly_ce_q[lf] <= (tap_q < cent_q[lf]);
                        tap_q <= tap_q + 1'b1;
                        if (tap_q == TAPS_T - 1'b1) begin
                            spi_word_q <= TP_SYNC;
                            st_q       <= S_SPI2;
                        end
                    end
                end
                // word boundaries: found in one period, held for LOCK periods
                S_FIND: if (per) begin
                    if (&fnd) begin
                        for (lf = 0; lf < NL; lf = lf + 1) b_q[lf] <= bnew[lf];
                        cnt_q <= {CNT_W{1'b0}};
                        st_q  <= S_LOCK;
                    end else begin
                        err_q <= 1'b1;
                        spi_word_q <= TP_DESKEW;
                        st_q  <= S_SPI1;
                    end
                end
                S_LOCK: if (per) begin
                    cnt_q <= cnt_q + 1'b1;
                    if (!(&hold)) begin
                        err_q <= 1'b1;
                        spi_word_q <= TP_DESKEW;
                        st_q  <= S_SPI1;
                    end else if (cnt_q == LOCK_C) begin
                        sp_q <= sp_new;
                        spi_word_q <= TP_NORMAL;
                        st_q       <= S_SPI3;
                    end
                end
                S_RUN: if (per) begin
                    for (lf = COLS; lf < NL; lf = lf + 1)
                        if (!hold[lf]) lost_q <= 1'b1;
                end
                default: st_q <= S_SPI1;
            endcase
        end
    end

    // ---------------------------------------------------------------- output words
    reg  [ADC_BITS-1:0] w_q [0:COLS-1];
    reg                 stb_q;
    reg  [ADC_BITS-1:0] pw_q [0:COLS-1];     // the lane's word of the previous period
    reg  [ADC_BITS-1:0] cur  [0:COLS-1];     // the lane's latest complete word
    reg  [ADC_BITS-1:0] wraw [0:COLS-1];
    reg  [ADC_BITS-1:0] wsel [0:COLS-1];
    always @(*) begin
        for (lo = 0; lo < COLS; lo = lo + 1) begin
            cur[lo]  = hist_q[lo][{{(E_W-B_W){1'b0}}, b_q[lo]} +: ADC_BITS];
            wraw[lo] = sp_q[lo] ? pw_q[lo] : cur[lo];
            for (bo = 0; bo < ADC_BITS; bo = bo + 1)
                wsel[lo][bo] = (LSB_FIRST != 0) ? wraw[lo][ADC_BITS-1-bo] : wraw[lo][bo];
        end
    end
    always @(posedge clk) begin
        stb_q <= per;
        if (per)
            for (lq = 0; lq < COLS; lq = lq + 1) begin
                pw_q[lq] <= cur[lq];
                w_q[lq]  <= wsel[lq];
            end
    end
    genvar g;
    generate
        for (g = 0; g < COLS; g = g + 1) begin : g_out
            assign adc_o[g*ADC_BITS +: ADC_BITS] = w_q[g];
        end
    endgenerate

    fmt_spi_wr #(.WORD_W(16), .LANES(1), .DIV(SPI_DIV)) u_spi (
        .clk(clk), .rst(rst), .start_i(spi_start_q), .data_i(spi_word_q), .busy_o(spi_busy),
        .sclk_o(spi_sclk_o), .sdata_o(spi_sdata_o), .cs_n_o(spi_cs_n_o));

    assign word_stb_o = stb_q;
    assign trained_o  = trained_q;
    assign err_o      = err_q;
    assign lost_o     = lost_q;
    assign dly_rst_o  = dly_rst_q;
    assign dly_ce_o   = dly_ce_q;
    assign dly_inc_o  = dly_inc_q;
endmodule
`default_nettype wire
