// fmt_interp -- fine touches: Von Neumann / Moore paraboloid fits of each coarse-touch
// candidate's 3x3 neighbourhood (paper Eq. 3-7), ellipse of the half-height contour,
// bias correction.  Bit-exact twin: fmt.interp.interp_fixed (sim/fmt/interp.py, whose
// docstring is the full arithmetic specification; summary below).
//
// Fully pipelined: one candidate per clock in, touches out in the same order after
// LAT = 24 clock cycles (cand_valid_i -> tp_valid_o, cand_eof_i -> tp_eof_o likewise).
// No stall and no per-frame state: a frame of n candidates (n <= the contact limit)
// occupies the input for n cycles, far below 768 clk per frame (worst case: the contact
// limit in cycles).  Products: each on 18 x 18 multipliers (DSP48E / MULT18X18D) with
// registered operands and registered partial products; a product wider than 18 x 18 is
// split over several multipliers (fmt_interp_mul) whose 17-bit-shifted sum has its own
// stage.  Constant factors are shifts and adds, except p * KQ (one multiplier).
// Stages: s1 inputs, s2 sums, s3 coefficients; position: s4 partial products, s5
// products, s6 Moore numerators / denominator, s7 fit selection, s8 |numerator|,
// s9..s18 dividers, s19 rounding, s20..s21 bias table (block RAM), s22 offset,
// s23 coordinates; ellipse: s4 normalisation, s5 products, s6..s8 cubic products,
// s9 G, CORDIC s5..s17, s18 pp, log2 s19..s21, s22 log sums, exp to s24.
//
// Position (per axis): Moore fit x_f = (6be - 8cd) / (16ac - 9b^2) when Moore mode, no
// neighbour missing, a < 0 and 16ac - 9b^2 > 0; else the Von Neumann fit
// (z[0][+1] - z[0][-1]) / (2 (2 z00 - z[0][+1] - z[0][-1])) when both neighbours exist
// and its denominator is > 0; one neighbour missing: the one-sided estimate from the
// ratio neighbour / z00 (same divider, edge table); else 0 (cell centre).  |offset| =
// round half up of a 9-bit truncating quotient (fmt_interp_div) in 1/256 cell, clamped
// to 128 (0.5 cell) when >= 257/512; optional bias table (fmt_interp_bias_rom).
// tp_x_o = col * 256 + offset clamped to [0, (COLS-1) * 256], tp_y_o likewise: cells,
// 8 fractional bits.
// Ellipse (Moore fit only): coefficients normalised to ~10-bit cells, G = F_v * 36 dm,
// CORDIC (fmt_interp_cordic) for |(2(a-c), 3b)| and 1/2 atan2(B, A - C), log2 ROMs
// (fmt_interp_lg) and an exp2 ROM (fmt_interp_exp) for the semi-axes
// sqrt(F_v / (2 |lambda|)): tp_axis_major_o / tp_axis_minor_o in cells Q8.8 (0xFFFF =
// saturated), tp_angle_o in pi/256 (0..255 = 0..pi).  0 when not defined.
// tp_strength_o = the centre cell z00.  tp_flags_o: bit 0 fallback (Moore fit rejected,
// Von Neumann denominator <= 0, or offset clamped), bit 1 saturated cell (2^HM_W - 1) in
// the 3x3, bit 2 edge (a neighbour missing), bit 3 Moore fit used; bits 7:4 zero.
`default_nettype none
`include "fmt_defaults.vh"

module fmt_interp #(
    parameter ROWS    = `FMT_ROWS,      // sensor rows (y)
    parameter COLS    = `FMT_COLS,      // sensor columns (x)
    parameter HM_W    = `FMT_HM_W,      // heat-map cell width (unsigned), >= 10
    parameter FRAME_W = 16,             // frame number width
    parameter CNT_W   = 8,              // candidate count width (passed through)
    parameter ROW_W   = (ROWS > 1) ? $clog2(ROWS) : 1,  // row index width
    parameter COL_W   = (COLS > 1) ? $clog2(COLS) : 1   // column index width
) (
    input  wire                 clk,            // processing clock
    input  wire                 rst,            // synchronous active-high reset
    // run-time settings (sampled with each candidate)
    input  wire                 moore_i,        // 1 = Moore fit (Eq. 5-6), 0 = Von Neumann (Eq. 3-4)
    input  wire                 bias_en_i,      // 1 = bias correction on
    // candidate stream (fmt_localmax)
    input  wire                 cand_valid_i,   // one candidate this cycle
    input  wire [FRAME_W-1:0]   cand_frame_i,   // frame number (with cand_valid_i and cand_eof_i)
    input  wire [ROW_W-1:0]     cand_row_i,     // row of the centre cell
    input  wire [COL_W-1:0]     cand_col_i,     // column of the centre cell
    input  wire [9*HM_W-1:0]    cand_z_i,       // z[dy][dx] at [((dy+1)*3+dx+1)*HM_W +: HM_W]
    input  wire [8:0]           cand_missing_i, // bit k = neighbour k outside the sensor
    input  wire                 cand_eof_i,     // end of the frame's candidates (pulse)
    input  wire [CNT_W-1:0]     cand_count_i,   // candidates of the frame (with cand_eof_i)
    input  wire                 cand_overflow_i, // contact limit hit (with cand_eof_i)
    // touch stream (fmt_tracker)
    output wire                 tp_valid_o,     // one touch this cycle
    output wire [FRAME_W-1:0]   tp_frame_o,     // frame number (with tp_valid_o and tp_eof_o)
    output wire [15:0]          tp_x_o,         // column position, cells Q8.8 from cell (0,0)'s centre
    output wire [15:0]          tp_y_o,         // row position, cells Q8.8
    output wire [HM_W-1:0]      tp_strength_o,  // centre (peak) cell value
    output wire [15:0]          tp_axis_major_o, // semi-major axis of the half-height contour, Q8.8
    output wire [15:0]          tp_axis_minor_o, // semi-minor axis, Q8.8
    output wire [7:0]           tp_angle_o,     // major-axis angle, pi/256 units
    output wire [7:0]           tp_flags_o,     // see header
    output wire                 tp_eof_o,       // cand_eof_i delayed by LAT
    output wire [CNT_W-1:0]     tp_count_o,     // cand_count_i delayed by LAT
    output wire                 tp_overflow_o   // cand_overflow_i delayed by LAT
);
    // ---- constants shared with the model (sim/tests/test_interp.py checks them) ----
    localparam integer KQ = 6745;
    localparam integer LC_MAJ = 58592;
    localparam integer LC_MIN = 45608;
    localparam integer ZN  = 10;        // normalised cell width of the ellipse path
    localparam integer QW  = 9;         // offset quotient bits
    localparam integer LAT = 24;        // total latency

    // ---- widths ---------------------------------------------------------------------
    localparam Z    = HM_W;
    localparam CSW  = Z + 2;            // sum of three cells (unsigned)
    localparam CW   = Z + 4;            // a, b, c, d, e (signed): |a| <= 6 (2^Z - 1)
    localparam BWD  = Z + 2;            // significant bits of b (signed): |b| <= 2 (2^Z - 1)
    localparam DEW  = Z + 3;            // significant bits of d, e (signed): |d| <= 3 (2^Z - 1)
    localparam FW   = Z + 7;            // f (signed): -16 M .. 52 M
    localparam VW   = Z + 4;            // Von Neumann num / den (signed)
    localparam PRW  = 2 * CW;           // products of coefficients
    localparam PW   = 2 * Z + 11;       // 6be - 8cd, 16ac - 9b^2 (signed): <= 612 M^2
    localparam NW   = 15;               // normalised a..e (signed, |.| <= 6 * 2^10)
    localparam FNW  = 18;               // normalised f
    localparam N2W  = 2 * NW;           // normalised products
    localparam DMW  = 32;               // normalised dm (signed, < 6.4e8)
    localparam N3W  = NW + N2W;         // cn * dn^2 etc.
    localparam QNW  = N3W + 1;          // qn (signed, < 2.9e11)
    localparam GW   = 50;               // G (signed, < 3.8e13)
    localparam IW   = 21;               // CORDIC input (signed, <= 393216)
    localparam PPW  = 32;               // pp (signed, < 3.4e8)
    localparam LW   = 22;               // log sums (signed)
    localparam SHW  = 6;                // normalisation shift

    // =================================================================================
    // s1: input registers (missing neighbours forced to 0)
    // =================================================================================
    reg [Z-1:0]         s1_z [0:8];
    reg [8:0]           s1_miss;
    reg [ROW_W-1:0]     s1_row;
    reg [COL_W-1:0]     s1_col;
    reg                 s1_moore, s1_bias;
    integer k;
    always @(posedge clk) begin
        for (k = 0; k < 9; k = k + 1)
            s1_z[k] <= cand_missing_i[k] ? {Z{1'b0}} : cand_z_i[k*Z +: Z];
        s1_miss  <= cand_missing_i;
        s1_row   <= cand_row_i;
        s1_col   <= cand_col_i;
        s1_moore <= moore_i;
        s1_bias  <= bias_en_i;
    end

    // valid pipeline and the pass-through of frame / eof / count / overflow
    wire [1:0] ctl_q;
    fmt_interp_dly #(.W(2), .N(LAT), .RST(1)) u_dly_ctl (
        .clk(clk), .rst(rst), .d_i({cand_valid_i, cand_eof_i}), .q_o(ctl_q));
    fmt_interp_dly #(.W(FRAME_W + CNT_W + 1), .N(LAT), .RST(0)) u_dly_frm (
        .clk(clk), .rst(rst), .d_i({cand_frame_i, cand_count_i, cand_overflow_i}),
        .q_o({tp_frame_o, tp_count_o, tp_overflow_o}));
    assign tp_valid_o = ctl_q[1];
    assign tp_eof_o   = ctl_q[0];

    // =================================================================================
    // s2: sums, Von Neumann terms, flags, normalisation shift
    // =================================================================================
    // z index k = (dy+1)*3 + (dx+1): 0 = (-1,-1), 1 = (-1,0), 2 = (-1,+1), 3 = (0,-1),
    // 4 = centre, 5 = (0,+1), 6 = (+1,-1), 7 = (+1,0), 8 = (+1,+1)
    wire [CSW-1:0] cs0 = {2'b0, s1_z[0]} + {2'b0, s1_z[3]} + {2'b0, s1_z[6]};
    wire [CSW-1:0] cs1 = {2'b0, s1_z[1]} + {2'b0, s1_z[4]} + {2'b0, s1_z[7]};
    wire [CSW-1:0] cs2 = {2'b0, s1_z[2]} + {2'b0, s1_z[5]} + {2'b0, s1_z[8]};
    wire [CSW-1:0] rs0 = {2'b0, s1_z[0]} + {2'b0, s1_z[1]} + {2'b0, s1_z[2]};
    wire [CSW-1:0] rs1 = {2'b0, s1_z[3]} + {2'b0, s1_z[4]} + {2'b0, s1_z[5]};
    wire [CSW-1:0] rs2 = {2'b0, s1_z[6]} + {2'b0, s1_z[7]} + {2'b0, s1_z[8]};
    wire [Z:0]     dg  = {1'b0, s1_z[8]} + {1'b0, s1_z[0]};     // xy = +1 corners
    wire [Z:0]     ad  = {1'b0, s1_z[2]} + {1'b0, s1_z[6]};     // xy = -1 corners
    wire [Z+1:0]   edg = {2'b0, s1_z[1]} + {2'b0, s1_z[3]} + {2'b0, s1_z[5]} + {2'b0, s1_z[7]};
    wire [Z+1:0]   crn = {1'b0, dg} + {1'b0, ad};
    wire signed [VW-1:0] z4s = {{(VW-Z){1'b0}}, s1_z[4]};
    wire signed [VW-1:0] z3s = {{(VW-Z){1'b0}}, s1_z[3]};
    wire signed [VW-1:0] z5s = {{(VW-Z){1'b0}}, s1_z[5]};
    wire signed [VW-1:0] z1s = {{(VW-Z){1'b0}}, s1_z[1]};
    wire signed [VW-1:0] z7s = {{(VW-Z){1'b0}}, s1_z[7]};

    reg [Z-1:0] orv;
    reg         sat_d;
    reg [SHW-1:0] sh_d;
    integer j;
    /* verilator lint_off UNUSEDSIGNAL */ // jt: only its low SHW bits are the shift
    integer jt;
    /* verilator lint_on UNUSEDSIGNAL */
    always @(*) begin
        jt = 0;
        orv = {Z{1'b0}};
        sat_d = 1'b0;
        for (j = 0; j < 9; j = j + 1) begin
            orv = orv | s1_z[j];
            if (!s1_miss[j] && (&s1_z[j])) sat_d = 1'b1;
        end
        // sh = max(0, bitlen(orv) - ZN)
        sh_d = {SHW{1'b0}};
        for (j = ZN; j < Z; j = j + 1)
            if (orv[j]) begin
                jt = j - ZN + 1;
                sh_d = jt[SHW-1:0];
            end
    end

    reg [CSW-1:0]        s2_cs0, s2_cs1, s2_cs2, s2_rs0, s2_rs1, s2_rs2;
    reg [Z:0]            s2_dg, s2_ad;
    reg [Z+1:0]          s2_edg, s2_crn;
    reg [Z-1:0]          s2_z4;
    reg signed [VW-1:0]  s2_nvx, s2_dvx, s2_nvy, s2_dvy;
    reg                  s2_mxl, s2_mxh, s2_myl, s2_myh, s2_edge, s2_sat, s2_moore, s2_bias;
    reg [Z-1:0]          s2_znx, s2_zny;    // the present neighbour of a one-sided axis
    reg [SHW-1:0]        s2_sh;
    always @(posedge clk) begin
        s2_cs0 <= cs0; s2_cs1 <= cs1; s2_cs2 <= cs2;
        s2_rs0 <= rs0; s2_rs1 <= rs1; s2_rs2 <= rs2;
        s2_dg  <= dg;  s2_ad  <= ad;  s2_edg <= edg; s2_crn <= crn;
        s2_z4  <= s1_z[4];
        s2_nvx <= z5s - z3s;
        s2_dvx <= (((z4s <<< 1) - z5s) - z3s) <<< 1;
        s2_nvy <= z7s - z1s;
        s2_dvy <= (((z4s <<< 1) - z7s) - z1s) <<< 1;
        s2_mxl <= s1_miss[3]; s2_mxh <= s1_miss[5];
        s2_myl <= s1_miss[1]; s2_myh <= s1_miss[7];
        s2_znx <= s1_miss[3] ? s1_z[5] : s1_z[3];
        s2_zny <= s1_miss[1] ? s1_z[7] : s1_z[1];
        s2_edge <= |s1_miss;
        s2_sat <= sat_d;
        s2_sh  <= sh_d;
        s2_moore <= s1_moore;
        s2_bias  <= s1_bias;
    end

    // =================================================================================
    // s3: coefficients a..f (x36 / x24 / x6 scaled, see fmt.interp.coeffs)
    // =================================================================================
    wire signed [CW-1:0] cs0s = {{(CW-CSW){1'b0}}, s2_cs0};
    wire signed [CW-1:0] cs1s = {{(CW-CSW){1'b0}}, s2_cs1};
    wire signed [CW-1:0] cs2s = {{(CW-CSW){1'b0}}, s2_cs2};
    wire signed [CW-1:0] rs0s = {{(CW-CSW){1'b0}}, s2_rs0};
    wire signed [CW-1:0] rs1s = {{(CW-CSW){1'b0}}, s2_rs1};
    wire signed [CW-1:0] rs2s = {{(CW-CSW){1'b0}}, s2_rs2};
    wire signed [FW-1:0] z4f  = {{(FW-Z){1'b0}}, s2_z4};
    wire signed [FW-1:0] edgf = {{(FW-Z-2){1'b0}}, s2_edg};
    wire signed [FW-1:0] crnf = {{(FW-Z-2){1'b0}}, s2_crn};

    reg signed [CW-1:0]  s3_a, s3_b, s3_c, s3_d, s3_e;
    reg signed [FW-1:0]  s3_f;
    reg signed [VW-1:0]  s3_nvx, s3_dvx, s3_nvy, s3_dvy;
    reg                  s3_mxl, s3_mxh, s3_myl, s3_myh, s3_edge, s3_sat, s3_moore, s3_bias;
    reg [Z-1:0]          s3_znx, s3_zny, s3_z4;
    reg [SHW-1:0]        s3_sh;
    always @(posedge clk) begin
        s3_a <= cs0s + cs2s - (cs1s <<< 1);
        s3_c <= rs0s + rs2s - (rs1s <<< 1);
        s3_b <= $signed({{(CW-Z-1){1'b0}}, s2_dg}) - $signed({{(CW-Z-1){1'b0}}, s2_ad});
        s3_d <= cs2s - cs0s;
        s3_e <= rs2s - rs0s;
        s3_f <= (z4f <<< 4) + (z4f <<< 2) + (edgf <<< 3) - (crnf <<< 2);   // 20 z00 + 8 edg - 4 crn
        s3_nvx <= s2_nvx; s3_dvx <= s2_dvx; s3_nvy <= s2_nvy; s3_dvy <= s2_dvy;
        s3_mxl <= s2_mxl; s3_mxh <= s2_mxh; s3_myl <= s2_myl; s3_myh <= s2_myh;
        s3_znx <= s2_znx; s3_zny <= s2_zny; s3_z4 <= s2_z4;
        s3_edge <= s2_edge; s3_sat <= s2_sat;
        s3_moore <= s2_moore; s3_bias <= s2_bias; s3_sh <= s2_sh;
    end

    // =================================================================================
    // s4 .. s5: products of the position path (fmt_interp_mul: operands s3, partial
    // products s4, products s5); normalised coefficients (ellipse path) s4
    // =================================================================================
    wire signed [PRW-1:0] s5_be, s5_cd, s5_bd, s5_ae, s5_ac, s5_bb;
    fmt_interp_mul #(.AW(BWD), .BW(DEW), .PW(PRW)) u_mul_be (
        .clk(clk), .a_i(s3_b[BWD-1:0]), .b_i(s3_e[DEW-1:0]), .p_o(s5_be));
    fmt_interp_mul #(.AW(CW), .BW(DEW), .PW(PRW)) u_mul_cd (
        .clk(clk), .a_i(s3_c), .b_i(s3_d[DEW-1:0]), .p_o(s5_cd));
    fmt_interp_mul #(.AW(BWD), .BW(DEW), .PW(PRW)) u_mul_bd (
        .clk(clk), .a_i(s3_b[BWD-1:0]), .b_i(s3_d[DEW-1:0]), .p_o(s5_bd));
    fmt_interp_mul #(.AW(CW), .BW(DEW), .PW(PRW)) u_mul_ae (
        .clk(clk), .a_i(s3_a), .b_i(s3_e[DEW-1:0]), .p_o(s5_ae));
    fmt_interp_mul #(.AW(CW), .BW(CW), .PW(PRW)) u_mul_ac (
        .clk(clk), .a_i(s3_a), .b_i(s3_c), .p_o(s5_ac));
    fmt_interp_mul #(.AW(BWD), .BW(BWD), .PW(PRW)) u_mul_bb (
        .clk(clk), .a_i(s3_b[BWD-1:0]), .b_i(s3_b[BWD-1:0]), .p_o(s5_bb));

    // side information of the position path: s3 -> s6
    localparam SIW = 4 * VW + 3 * Z + 9;
    wire signed [VW-1:0] s6_nvx, s6_dvx, s6_nvy, s6_dvy;
    wire                 s6_mxl, s6_mxh, s6_myl, s6_myh, s6_edge, s6_sat, s6_moore, s6_bias, s6_aneg;
    wire [Z-1:0]         s6_znx, s6_zny, s6_z4;
    fmt_interp_dly #(.W(SIW), .N(3), .RST(0)) u_dly_side (
        .clk(clk), .rst(rst),
        .d_i({s3_nvx, s3_dvx, s3_nvy, s3_dvy, s3_mxl, s3_mxh, s3_myl, s3_myh, s3_edge,
              s3_sat, s3_moore, s3_bias, s3_a[CW-1], s3_znx, s3_zny, s3_z4}),
        .q_o({s6_nvx, s6_dvx, s6_nvy, s6_dvy, s6_mxl, s6_mxh, s6_myl, s6_myh, s6_edge,
              s6_sat, s6_moore, s6_bias, s6_aneg, s6_znx, s6_zny, s6_z4}));

    reg signed [NW-1:0]  s4_an, s4_bn, s4_cn, s4_dn, s4_en;
    reg signed [FW-1:0]  s4_f;
    reg [SHW-1:0]        s4_sh;
    /* verilator lint_off WIDTHTRUNC */ // the shifted coefficients fit NW bits (see widths)
    always @(posedge clk) begin
        s4_an <= s3_a >>> s3_sh;
        s4_bn <= s3_b >>> s3_sh;
        s4_cn <= s3_c >>> s3_sh;
        s4_dn <= s3_d >>> s3_sh;
        s4_en <= s3_e >>> s3_sh;
        s4_f  <= s3_f;
        s4_sh <= s3_sh;
    end
    /* verilator lint_on WIDTHTRUNC */

    // CORDIC on (2 (an - cn), 3 bn) << 4: magnitude at s17, angle at s17
    wire signed [NW-1:0] amc = s4_an - s4_cn;      // |an - cn| <= 12288 fits NW bits
    wire signed [IW-1:0] cu = {{(IW-NW-1){amc[NW-1]}}, amc, 1'b0} <<< 4;
    wire signed [IW-1:0] bn_i = {{(IW-NW){s4_bn[NW-1]}}, s4_bn};
    wire signed [IW-1:0] cv = ((bn_i <<< 1) + bn_i) <<< 4;   // 3 bn << 4 (no multiplier)
    wire [IW+1:0] cor_mag;
    wire [15:0]   cor_ang;
    /* verilator lint_off PINCONNECTEMPTY */ // the LAT-long control delay carries valid
    fmt_interp_cordic #(.IW(IW), .N(12)) u_cordic (
        .clk(clk), .rst(rst), .valid_i(1'b0), .u_i(cu), .v_i(cv),
        .valid_o(), .mag_o(cor_mag), .ang_o(cor_ang));
    /* verilator lint_on PINCONNECTEMPTY */

    // =================================================================================
    // s5: normalised products (one 18 x 18 multiplier each, operands s4, product s5)
    // =================================================================================
    reg signed [N2W-1:0] s5_acn, s5_bbn, s5_ddn, s5_den, s5_een;
    reg signed [NW-1:0]  s5_an, s5_bn, s5_cn;
    reg signed [FW-1:0]  s5_f;
    reg [SHW-1:0]        s5_sh;
    reg signed [NW:0]    s5_s;
    always @(posedge clk) begin
        s5_acn <= s4_an * s4_cn;
        s5_bbn <= s4_bn * s4_bn;
        s5_ddn <= s4_dn * s4_dn;
        s5_den <= s4_dn * s4_en;
        s5_een <= s4_en * s4_en;
        s5_an <= s4_an; s5_bn <= s4_bn; s5_cn <= s4_cn;
        s5_f  <= s4_f;  s5_sh <= s4_sh;
        s5_s  <= {s4_an[NW-1], s4_an} + {s4_cn[NW-1], s4_cn};
    end

    // =================================================================================
    // s6: numerators / denominator of the Moore fit; dm_n, f_n
    // =================================================================================
    wire signed [PW-1:0] be_w = {{(PW-PRW){s5_be[PRW-1]}}, s5_be};
    wire signed [PW-1:0] cd_w = {{(PW-PRW){s5_cd[PRW-1]}}, s5_cd};
    wire signed [PW-1:0] bd_w = {{(PW-PRW){s5_bd[PRW-1]}}, s5_bd};
    wire signed [PW-1:0] ae_w = {{(PW-PRW){s5_ae[PRW-1]}}, s5_ae};
    wire signed [PW-1:0] ac_w = {{(PW-PRW){s5_ac[PRW-1]}}, s5_ac};
    wire signed [PW-1:0] bb_w = {{(PW-PRW){s5_bb[PRW-1]}}, s5_bb};
    wire signed [DMW-1:0] acn_w = {{(DMW-N2W){s5_acn[N2W-1]}}, s5_acn};
    wire signed [DMW-1:0] bbn_w = {{(DMW-N2W){s5_bbn[N2W-1]}}, s5_bbn};

    reg signed [PW-1:0]  s6_nmx, s6_nmy, s6_dm;
    reg signed [DMW-1:0] s6_dmn;
    reg signed [FNW-1:0] s6_fn;
    /* verilator lint_off WIDTHTRUNC */ // dm_n fits DMW bits, f_n FNW bits
    always @(posedge clk) begin
        // constant factors as shifts and adds
        s6_nmx <= (be_w <<< 2) + (be_w <<< 1) - (cd_w <<< 3);
        s6_nmy <= (bd_w <<< 2) + (bd_w <<< 1) - (ae_w <<< 3);
        s6_dm  <= (ac_w <<< 4) - (bb_w <<< 3) - bb_w;
        s6_dmn <= (acn_w <<< 4) - (bbn_w <<< 3) - bbn_w;
        s6_fn  <= s5_f >>> s5_sh;
    end
    /* verilator lint_on WIDTHTRUNC */

    // ellipse products: operands s5 / s6, partial products s6 / s7, products s7 / s8
    wire signed [N3W-1:0] s7_cdd, s7_bde, s7_aee;
    fmt_interp_mul #(.AW(NW), .BW(N2W), .PW(N3W)) u_mul_cdd (
        .clk(clk), .a_i(s5_cn), .b_i(s5_ddn), .p_o(s7_cdd));
    fmt_interp_mul #(.AW(NW), .BW(N2W), .PW(N3W)) u_mul_bde (
        .clk(clk), .a_i(s5_bn), .b_i(s5_den), .p_o(s7_bde));
    fmt_interp_mul #(.AW(NW), .BW(N2W), .PW(N3W)) u_mul_aee (
        .clk(clk), .a_i(s5_an), .b_i(s5_een), .p_o(s7_aee));
    wire signed [GW-1:0] s8_fdm;
    fmt_interp_mul #(.AW(FNW), .BW(DMW), .PW(GW)) u_mul_fdm (
        .clk(clk), .a_i(s6_fn), .b_i(s6_dmn), .p_o(s8_fdm));

    // =================================================================================
    // s7: fit selection per axis (signed numerator, denominator, flags)
    // =================================================================================
    wire moore_ok = s6_moore & ~s6_edge & s6_aneg & (s6_dm > 0);
    wire s6_mx = s6_mxl | s6_mxh;
    wire s6_my = s6_myl | s6_myh;
    wire z4_pos = |s6_z4;
    // one neighbour missing: one-sided ratio estimate (num = +-z_nb, den = z00)
    wire ex = ~moore_ok & (s6_mxl ^ s6_mxh) & z4_pos;
    wire ey = ~moore_ok & (s6_myl ^ s6_myh) & z4_pos;
    wire vx_ok = ~s6_mx & (s6_dvx > 0);
    wire vy_ok = ~s6_my & (s6_dvy > 0);
    wire signed [PW-1:0] znx_w = {{(PW-Z){1'b0}}, s6_znx};
    wire signed [PW-1:0] zny_w = {{(PW-Z){1'b0}}, s6_zny};
    wire signed [PW-1:0] z4_w  = {{(PW-Z){1'b0}}, s6_z4};
    wire signed [PW-1:0] nvx_w = {{(PW-VW){s6_nvx[VW-1]}}, s6_nvx};
    wire signed [PW-1:0] dvx_w = {{(PW-VW){s6_dvx[VW-1]}}, s6_dvx};
    wire signed [PW-1:0] nvy_w = {{(PW-VW){s6_nvy[VW-1]}}, s6_nvy};
    wire signed [PW-1:0] dvy_w = {{(PW-VW){s6_dvy[VW-1]}}, s6_dvy};
    wire signed [PW-1:0] one_w = 1;
    wire signed [PW-1:0] numx = moore_ok ? s6_nmx : ex ? (s6_mxl ? znx_w : -znx_w)
                              : (vx_ok ? nvx_w : {PW{1'b0}});
    wire signed [PW-1:0] numy = moore_ok ? s6_nmy : ey ? (s6_myl ? zny_w : -zny_w)
                              : (vy_ok ? nvy_w : {PW{1'b0}});
    /* verilator lint_off UNUSEDSIGNAL */ // sign bits of den: only used when den > 0
    wire signed [PW-1:0] denx = moore_ok ? s6_dm  : ex ? z4_w : (vx_ok ? dvx_w : one_w);
    wire signed [PW-1:0] deny = moore_ok ? s6_dm  : ey ? z4_w : (vy_ok ? dvy_w : one_w);
    /* verilator lint_on UNUSEDSIGNAL */
    wire fb_d = (s6_moore & ~s6_edge & ~moore_ok)
              | (~moore_ok & ~s6_mx & ~(s6_dvx > 0))
              | (~moore_ok & ~s6_my & ~(s6_dvy > 0))
              | (~moore_ok & ((s6_mxl ^ s6_mxh) | (s6_myl ^ s6_myh)) & ~z4_pos);

    reg signed [PW-1:0]  s7_numx, s7_numy;
    reg [PW-2:0]         s7_denx, s7_deny;
    reg                  s7_fb, s7_mok, s7_edge, s7_sat, s7_bias, s7_ex, s7_ey;
    reg signed [DMW-1:0] s7_dmn;
    /* verilator lint_off WIDTHTRUNC */ // den > 0 fits PW-1 bits
    always @(posedge clk) begin
        s7_numx <= numx;
        s7_numy <= numy;
        s7_denx <= denx;
        s7_deny <= deny;
        s7_fb   <= fb_d;
        s7_mok  <= moore_ok;
        s7_edge <= s6_edge;
        s7_sat  <= s6_sat;
        s7_bias <= s6_bias;
        s7_ex   <= ex;
        s7_ey   <= ey;
        s7_dmn  <= s6_dmn;
    end
    /* verilator lint_on WIDTHTRUNC */

    // =================================================================================
    // s8: |numerator| and its sign; qn
    // =================================================================================
    wire signed [QNW-1:0] cdd_w = {{(QNW-N3W){s7_cdd[N3W-1]}}, s7_cdd};
    wire signed [QNW-1:0] bde_w = {{(QNW-N3W){s7_bde[N3W-1]}}, s7_bde};
    wire signed [QNW-1:0] aee_w = {{(QNW-N3W){s7_aee[N3W-1]}}, s7_aee};
    reg [PW-2:0]         s8_magx, s8_magy, s8_denx, s8_deny;
    reg                  s8_sgx, s8_sgy, s8_fb, s8_mok, s8_edge, s8_sat, s8_bias, s8_ex, s8_ey;
    reg signed [QNW-1:0] s8_qn;
    reg signed [DMW-1:0] s8_dmn;
    /* verilator lint_off WIDTHTRUNC */ // |num| fits PW-1 bits
    always @(posedge clk) begin
        // |num| = (num ^ sign) + sign: one adder
        s8_magx <= (s7_numx ^ {PW{s7_numx[PW-1]}}) + {{(PW-1){1'b0}}, s7_numx[PW-1]};
        s8_magy <= (s7_numy ^ {PW{s7_numy[PW-1]}}) + {{(PW-1){1'b0}}, s7_numy[PW-1]};
        s8_sgx  <= s7_numx[PW-1];
        s8_sgy  <= s7_numy[PW-1];
        s8_denx <= s7_denx;
        s8_deny <= s7_deny;
        s8_fb   <= s7_fb;
        s8_mok  <= s7_mok;
        s8_edge <= s7_edge;
        s8_sat  <= s7_sat;
        s8_bias <= s7_bias;
        s8_ex   <= s7_ex;
        s8_ey   <= s7_ey;
        s8_qn   <= (cdd_w <<< 1) - (bde_w <<< 1) - bde_w + (aee_w <<< 1);
        s8_dmn  <= s7_dmn;
    end
    /* verilator lint_on WIDTHTRUNC */

    // ---- offset dividers: q = floor(|num| * 512 / den), s9 .. s18 ----
    wire [QW-1:0] qx, qy;
    wire          ovx, ovy;
    fmt_interp_div #(.MAG_W(PW - 1), .DEN_W(PW - 1), .QW(QW)) u_divx (
        .clk(clk), .mag_i(s8_magx), .den_i(s8_denx), .quot_o(qx), .ovf_o(ovx));
    fmt_interp_div #(.MAG_W(PW - 1), .DEN_W(PW - 1), .QW(QW)) u_divy (
        .clk(clk), .mag_i(s8_magy), .den_i(s8_deny), .quot_o(qy), .ovf_o(ovy));

    // side information of the position path: s8 -> s18
    wire s18_sgx, s18_sgy, s18_mok, s18_fb, s18_edge, s18_sat, s18_bias, s18_ex, s18_ey;
    fmt_interp_dly #(.W(9), .N(QW + 1), .RST(0)) u_dly_pos (
        .clk(clk), .rst(rst),
        .d_i({s8_sgx, s8_sgy, s8_mok, s8_fb, s8_edge, s8_sat, s8_bias, s8_ex, s8_ey}),
        .q_o({s18_sgx, s18_sgy, s18_mok, s18_fb, s18_edge, s18_sat, s18_bias, s18_ex, s18_ey}));

    // =================================================================================
    // ellipse path s9: G = f_n dm_n - 12 qn
    // =================================================================================
    wire signed [GW-1:0] qn_w = {{(GW-QNW){s8_qn[QNW-1]}}, s8_qn};
    reg signed [GW-1:0]  s9_g;
    reg signed [DMW-1:0] s9_dmn;
    always @(posedge clk) begin
        s9_g   <= s8_fdm - (qn_w <<< 3) - (qn_w <<< 2);
        s9_dmn <= s8_dmn;
    end
    wire g_pos9  = ~s9_g[GW-1] & (|s9_g);
    wire dm_pos9 = ~s9_dmn[DMW-1] & (|s9_dmn);

    // the log2 blocks work at s18 .. s21 on delayed G and dm_n (their block-RAM read data
    // then goes straight into registers, not into a shift register)
    wire signed [GW-1:0]  g18;
    wire signed [DMW-1:0] dmn18;
    fmt_interp_dly #(.W(GW + DMW), .N(9), .RST(0)) u_dly_lg (
        .clk(clk), .rst(rst), .d_i({s9_g, s9_dmn}), .q_o({g18, dmn18}));
    wire [$clog2(GW)+11:0]  lg_g21;
    wire [$clog2(DMW)+11:0] lg_dm21;
    fmt_interp_lg #(.X_W(GW)) u_lg_g (.clk(clk), .x_i(g18), .lg_o(lg_g21));
    fmt_interp_lg #(.X_W(DMW)) u_lg_dm (.clk(clk), .x_i(dmn18), .lg_o(lg_dm21));
    wire pos_ok21;
    fmt_interp_dly #(.W(1), .N(12), .RST(0)) u_dly_pos9 (
        .clk(clk), .rst(rst), .d_i(g_pos9 & dm_pos9), .q_o(pos_ok21));

    // ---- pp = p * KQ + (|s| K << 8) at s18, p = -2 (an + cn) ----
    // p formed from the delayed sum at s16 (operand register), p * KQ at s17 (product
    // register at the multiplier), one adder at s18 (its P register)
    wire signed [NW:0] s15_s;
    fmt_interp_dly #(.W(NW + 1), .N(10), .RST(0)) u_dly_p (
        .clk(clk), .rst(rst), .d_i(s5_s), .q_o(s15_s));
    reg signed [NW+2:0]  s16_p;
    reg signed [PPW-1:0] s17_pkq, s18_pp;
    /* verilator lint_off WIDTHTRUNC */ // pp < 3.4e8 fits PPW bits
    always @(posedge clk) begin
        s16_p   <= -({{2{s15_s[NW]}}, s15_s} <<< 1);
        s17_pkq <= {{(PPW-NW-3){s16_p[NW+2]}}, s16_p} * KQ;
        s18_pp  <= s17_pkq + $signed({{(PPW-IW-2){1'b0}}, cor_mag} << 8);
    end
    /* verilator lint_on WIDTHTRUNC */
    wire pp_pos18 = ~s18_pp[PPW-1] & (|s18_pp);
    wire [$clog2(PPW)+11:0] lg_pp21;
    fmt_interp_lg #(.X_W(PPW)) u_lg_pp (.clk(clk), .x_i(s18_pp), .lg_o(lg_pp21));
    wire pp_pos21;
    fmt_interp_dly #(.W(1), .N(3), .RST(0)) u_dly_ppp (
        .clk(clk), .rst(rst), .d_i(pp_pos18), .q_o(pp_pos21));

    // ---- s22: log2 of the squared semi-axes ----
    wire signed [LW-1:0] lgg = {{(LW-$clog2(GW)-12){1'b0}}, lg_g21};
    wire signed [LW-1:0] lgd = {{(LW-$clog2(DMW)-12){1'b0}}, lg_dm21};
    wire signed [LW-1:0] lgp = {{(LW-$clog2(PPW)-12){1'b0}}, lg_pp21};
    localparam signed [LW-1:0] LCMAJ_W = LC_MAJ[LW-1:0];
    localparam signed [LW-1:0] LCMIN_W = LC_MIN[LW-1:0];
    // the sums go straight to the exp blocks' first registers (block-RAM address, k)
    wire signed [LW-1:0] lmaj = lgg + lgp - (lgd <<< 1) - LCMAJ_W;
    wire signed [LW-1:0] lmin = lgg - lgd - lgp + LCMIN_W;
    reg                 s22_ok;
    always @(posedge clk) s22_ok <= pos_ok21 & pp_pos21;
    wire [15:0] ax_maj24, ax_min24;
    fmt_interp_exp #(.LW(LW)) u_exp_maj (.clk(clk), .l_i(lmaj), .axis_o(ax_maj24));
    fmt_interp_exp #(.LW(LW)) u_exp_min (.clk(clk), .l_i(lmin), .axis_o(ax_min24));
    wire ell_ok24;
    fmt_interp_dly #(.W(1), .N(2), .RST(0)) u_dly_eok (
        .clk(clk), .rst(rst), .d_i(s22_ok), .q_o(ell_ok24));

    // ---- angle: ((z + 128) >> 8) mod 256 at s17 -> s24 ----
    /* verilator lint_off UNUSEDSIGNAL */ // the low byte only rounds
    wire [15:0] ang_r = cor_ang + 16'd128;
    /* verilator lint_on UNUSEDSIGNAL */
    wire [7:0] ang24;
    fmt_interp_dly #(.W(8), .N(7), .RST(0)) u_dly_ang (
        .clk(clk), .rst(rst), .d_i(ang_r[15:8]), .q_o(ang24));

    // =================================================================================
    // position s19: round / clamp; s20 .. s21: bias table (block RAM, output register);
    // s22: offset; s23: coordinates
    // =================================================================================
    // clamp (fit offsets only); the edge estimate indexes its table by q >> 1 (255 on
    // overflow, ratio >= 1)
    wire clx = ~s18_ex & (ovx | (qx >= 257));
    wire cly = ~s18_ey & (ovy | (qy >= 257));
    /* verilator lint_off UNUSEDSIGNAL */ // (q + 1) >> 1 for q <= 256: bits 8:1 only
    wire [QW:0] qx1 = {1'b0, qx} + 1'b1;
    wire [QW:0] qy1 = {1'b0, qy} + 1'b1;
    /* verilator lint_on UNUSEDSIGNAL */
    reg [7:0] s19_rx, s19_ry;
    reg       s19_sgx, s19_sgy, s19_mok, s19_bias, s19_ex, s19_ey;
    reg [3:0] s19_flags;
    always @(posedge clk) begin
        s19_rx  <= s18_ex ? (ovx ? 8'd255 : qx[8:1]) : (clx ? 8'd128 : qx1[8:1]);
        s19_ry  <= s18_ey ? (ovy ? 8'd255 : qy[8:1]) : (cly ? 8'd128 : qy1[8:1]);
        s19_ex  <= s18_ex;
        s19_ey  <= s18_ey;
        s19_sgx <= s18_sgx;
        s19_sgy <= s18_sgy;
        s19_mok <= s18_mok;
        s19_bias <= s18_bias;
        s19_flags <= {s18_mok, s18_edge, s18_sat, s18_fb | clx | cly};
    end
    wire [7:0] bx21, by21;
    fmt_interp_bias_rom u_bias_x (.clk(clk), .addr_i({s19_ex, s19_mok, s19_rx}), .data_o(bx21));
    fmt_interp_bias_rom u_bias_y (.clk(clk), .addr_i({s19_ey, s19_mok, s19_ry}), .data_o(by21));
    wire [7:0] rx21, ry21;
    wire       sgx21, sgy21, bias21, ex21, ey21;
    fmt_interp_dly #(.W(21), .N(2), .RST(0)) u_dly_rom (
        .clk(clk), .rst(rst),
        .d_i({s19_rx, s19_ry, s19_sgx, s19_sgy, s19_bias, s19_ex, s19_ey}),
        .q_o({rx21, ry21, sgx21, sgy21, bias21, ex21, ey21}));
    wire [ROW_W-1:0] row21;
    wire [COL_W-1:0] col21;
    fmt_interp_dly #(.W(ROW_W + COL_W), .N(20), .RST(0)) u_dly_rc (
        .clk(clk), .rst(rst), .d_i({s1_row, s1_col}), .q_o({row21, col21}));
    // s22: the offsets (table or rounded quotient) and their cells; s23: coordinates
    reg [7:0]        s22_ox, s22_oy;
    reg              s22_sgx, s22_sgy;
    reg [ROW_W-1:0]  s22_row;
    reg [COL_W-1:0]  s22_col;
    always @(posedge clk) begin
        s22_ox  <= (bias21 | ex21) ? bx21 : rx21;
        s22_oy  <= (bias21 | ey21) ? by21 : ry21;
        s22_sgx <= sgx21;
        s22_sgy <= sgy21;
        s22_row <= row21;
        s22_col <= col21;
    end
    wire signed [18:0] colq = {{(11-COL_W){1'b0}}, s22_col, 8'd0};
    wire signed [18:0] rowq = {{(11-ROW_W){1'b0}}, s22_row, 8'd0};
    wire signed [18:0] oxs  = {11'd0, s22_ox};
    wire signed [18:0] oys  = {11'd0, s22_oy};
    wire signed [18:0] xs = s22_sgx ? colq - oxs : colq + oxs;
    wire signed [18:0] ys = s22_sgy ? rowq - oys : rowq + oys;
    localparam signed [18:0] XMAX = (COLS - 1) * 256;
    localparam signed [18:0] YMAX = (ROWS - 1) * 256;
    reg [15:0] s23_x, s23_y;
    /* verilator lint_off WIDTHTRUNC */ // clamped values fit 16 bits
    always @(posedge clk) begin
        s23_x <= xs[18] ? 19'sd0 : (xs > XMAX ? XMAX : xs);
        s23_y <= ys[18] ? 19'sd0 : (ys > YMAX ? YMAX : ys);
    end
    /* verilator lint_on WIDTHTRUNC */
    fmt_interp_dly #(.W(32), .N(1), .RST(0)) u_dly_xy (
        .clk(clk), .rst(rst), .d_i({s23_x, s23_y}), .q_o({tp_x_o, tp_y_o}));
    wire [3:0] flags24;
    fmt_interp_dly #(.W(4), .N(5), .RST(0)) u_dly_flg (
        .clk(clk), .rst(rst), .d_i(s19_flags), .q_o(flags24));
    fmt_interp_dly #(.W(Z), .N(LAT - 1), .RST(0)) u_dly_str (
        .clk(clk), .rst(rst), .d_i(s1_z[4]), .q_o(tp_strength_o));

    wire ell24 = flags24[3] & ell_ok24;
    assign tp_flags_o      = {4'd0, flags24};
    assign tp_axis_major_o = ell24 ? ax_maj24 : 16'd0;
    assign tp_axis_minor_o = ell24 ? ax_min24 : 16'd0;
    assign tp_angle_o      = ell24 ? ang24 : 8'd0;
endmodule
`default_nettype wire
