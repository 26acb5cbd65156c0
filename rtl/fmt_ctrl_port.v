// fmt_ctrl_port -- control/monitor port: UART, frame parser, responder, register-bus
// and block-read master, decimated event stream.  Protocol: docs/PROTOCOL.md; model
// twin and host side: sim/fmt/protocol.py.
//
// Frame (both directions): SYNC 0xA5, LEN (2, payload bytes), SEQ, CMD, PAYLOAD, CRC (2,
// CRC-16/CCITT-FALSE over LEN..PAYLOAD), big-endian.  Commands: INFO 0x01, READ 0x02,
// WRITE 0x03, BLKREAD 0x04, STREAM 0x05; a reply echoes SEQ with CMD | 0x80, an error
// reply has CMD 0xFF and payload {code, request CMD}; event frames have CMD 0xE0.
//
// Receive path: fmt_uart_rx -> a 2^FIFO_AW-byte FIFO (bytes arriving while a reply is
// sent are kept; distributed RAM) -> a head register (one more byte) -> the parser,
// which sees only flip-flops: a byte reaches the parser 2 cycles after valid_o.  The request payload is buffered (PAYLOAD_MAX bytes,
// distributed RAM) and nothing is executed before the CRC has been checked, so a bad
// frame never writes a register.  Errors (each counted in err_count_o, saturating, and
// answered by one ERROR reply):
//   CRC (frame complete, CRC wrong) -> reply, hunt for the next SYNC;
//   TIMEOUT (line idle TIMEOUT_BITS bit times inside a frame) -> reply, hunt;
//   LEN (LEN > PAYLOAD_MAX: reply at once, then discard bytes until the line has been
//        idle for the timeout; LEN or COUNT wrong for the command: reply, hunt);
//   CMD (unknown command with a good CRC) -> reply, hunt;
//   FRAMING (UART stop bit low inside a frame), OVERFLOW (receive FIFO full) -> reply,
//        discard until idle;
//   JUNK (bytes outside a frame): one error per burst; replied (SEQ 0) when the line
//        goes idle for the timeout, only counted when a SYNC follows directly (so the
//        frame's own reply is the next frame on the wire).
//
// Register bus (to fmt_regfile): reg_we_o / reg_re_o one-cycle strobes with reg_addr_o,
// reg_wdata_o (all registered); reg_rdata_i is sampled 2 cycles after reg_re_o rises
// (the register file's registered read).  Block port: blk_req_o (one cycle) with
// blk_addr_o, one word per request; blk_rdata_i must be valid BLK_LAT cycles after the
// cycle in which blk_req_o is high (BLK_LAT = 1: a RAM with a registered read).
// Words go out big-endian.  A WRITE of k words writes ADDR, ADDR+1, ... one per 4
// cycles after the CRC check.
//
// Event stream (STREAM command on): when the parser is idle (no byte waiting, no frame
// in progress), an offered event (evs_valid_i) is taken (evs_ready_o) and sent as one
// event frame of EV_BYTES bytes (evs_data_i, most significant byte first) with a running
// SEQ.  With the stream off evs_ready_o is 1 (events are dropped; the core decimates
// with REPORT_PERIOD).  Timing at 115200 baud: an event frame (31 bytes) takes 2.7 ms; the
// default 128-byte receive FIFO holds any request (<= PAYLOAD_MAX + 7 bytes) arriving
// meanwhile.
`default_nettype none
`include "fmt_defaults.vh"

module fmt_ctrl_port #(
    parameter DIV          = 1085,          // clocks per UART bit (125 MHz / 1085 = 115207 baud)
    parameter TIMEOUT_BITS = 40,            // inter-byte timeout inside a frame, in bit times
    parameter PAYLOAD_MAX  = 64,            // request payload buffer, bytes (>= 8; WRITE of up to (PAYLOAD_MAX-2)/4 words)
    parameter FIFO_AW      = 7,             // receive FIFO depth 2^FIFO_AW bytes (distributed RAM)
    parameter BLK_LAT      = 1,             // block read latency: blk_rdata_i valid BLK_LAT cycles after blk_req_o (>= 1)
    parameter EV_BYTES     = 24,            // event payload bytes (multiple of 4)
    parameter REGMAP_ID    = 0,             // 16-bit register-map id reported by INFO
    parameter ROWS         = `FMT_ROWS,     // sensor size and comb, reported by INFO
    parameter COLS         = `FMT_COLS,
    parameter LOG2_N       = `FMT_LOG2_N,
    parameter HM_W         = `FMT_HM_W,
    parameter BIN_LO       = `FMT_BIN_LO,
    parameter BIN_STEP     = `FMT_BIN_STEP
) (
    input  wire                  clk,
    input  wire                  rst,            // synchronous, active high
    input  wire                  rxd_i,          // UART receive line (asynchronous)
    output wire                  txd_o,          // UART transmit line
    output reg                   reg_we_o,       // register write strobe
    output reg                   reg_re_o,       // register read strobe
    output reg  [15:0]           reg_addr_o,     // register word address
    output reg  [31:0]           reg_wdata_o,    // register write data
    input  wire [31:0]           reg_rdata_i,    // register read data (2 cycles after reg_re_o)
    output reg                   blk_req_o,      // block read request, one word
    output reg  [15:0]           blk_addr_o,     // block word address
    input  wire [31:0]           blk_rdata_i,    // block read data, BLK_LAT cycles after blk_req_o
    input  wire                  evs_valid_i,    // an event is offered
    input  wire [EV_BYTES*8-1:0] evs_data_i,     // the event payload, first byte in the MSBs
    output wire                  evs_ready_o,    // the event is taken (or dropped: stream off)
    output reg                   stream_en_o,    // event streaming on (STREAM command)
    output reg  [15:0]           err_count_o,    // protocol errors, saturating
    output reg  [7:0]            err_last_o,     // code of the last error
    output reg                   err_pulse_o     // one-cycle pulse per error
);

    // ---- constants ------------------------------------------------------------------
    localparam [7:0]  SYNC      = 8'hA5;
    localparam [15:0] VERSION   = 16'h0100;
    localparam [31:0] MAGIC     = 32'h464D5443;
    localparam [7:0]  C_INFO = 8'h01, C_READ = 8'h02, C_WRITE = 8'h03, C_BLKREAD = 8'h04,
                      C_STREAM = 8'h05, C_ERROR = 8'hFF, C_EVENT = 8'hE0;
    localparam [7:0]  E_CRC = 8'd1, E_TIMEOUT = 8'd2, E_LEN = 8'd3, E_CMD = 8'd4,
                      E_JUNK = 8'd5, E_FRAMING = 8'd6, E_OVERFLOW = 8'd7;
    localparam integer TMO_CLKS = TIMEOUT_BITS * DIV;
    localparam TW = $clog2(TMO_CLKS + 1);
    localparam [31:0] TMO_LAST = TMO_CLKS - 1;
    localparam PW = $clog2(PAYLOAD_MAX);
    localparam [15:0] PMAX16 = PAYLOAD_MAX;
    localparam [15:0] EVLEN16 = EV_BYTES;
    localparam EV_W = EV_BYTES * 8;
    localparam [7:0] BLK_LAT8 = BLK_LAT;
    localparam [7:0] ROWS8 = ROWS, COLS8 = COLS, LOG2_N8 = LOG2_N, HM_W8 = HM_W,
                     BIN_LO8 = BIN_LO, BIN_STEP8 = BIN_STEP;
    localparam [15:0] REGMAP_ID16 = REGMAP_ID;

    // states
    localparam [4:0] S_HUNT = 5'd0, S_LENH = 5'd1, S_LENL = 5'd2, S_SEQ = 5'd3, S_CMD = 5'd4,
                     S_PAY = 5'd5, S_CRCH = 5'd6, S_CRCL = 5'd7, S_DISCARD = 5'd8,
                     S_EXEC = 5'd9, S_WR = 5'd10,
                     S_TSYNC = 5'd16, S_TLENH = 5'd17, S_TLENL = 5'd18, S_TSEQ = 5'd19,
                     S_TCMD = 5'd20, S_TFETCH = 5'd21, S_TWAIT = 5'd22, S_TPAY = 5'd23,
                     S_TCRCH = 5'd24, S_TCRCL = 5'd25;
    // reply payload sources
    localparam [2:0] SRC_NONE = 3'd0, SRC_INFO = 3'd1, SRC_REG = 3'd2, SRC_BLK = 3'd3,
                     SRC_ERR = 3'd4, SRC_EVT = 3'd5;

    // ---- UART ---------------------------------------------------------------------------
    wire [7:0] rx_data;
    wire       rx_valid;
    wire       rx_ferr;
    wire       tx_ready;
    reg        tx_valid;
    reg  [7:0] tx_data;

    fmt_uart_rx #(.DIV(DIV)) u_rx (
        .clk(clk), .rst(rst), .rxd_i(rxd_i),
        .data_o(rx_data), .valid_o(rx_valid), .frame_err_o(rx_ferr));

    fmt_uart_tx #(.DIV(DIV)) u_tx (
        .clk(clk), .rst(rst), .data_i(tx_data), .valid_i(tx_valid),
        .ready_o(tx_ready), .txd_o(txd_o));

    // ---- receive FIFO ({frame error, byte}) and its head register ---------------------------
    // The head register takes the oldest byte of the RAM whenever it is empty or being
    // consumed (pop); the parser reads only the head.
    (* ram_style = "distributed" *)
    reg [8:0]       fifo_mem [0:(1 << FIFO_AW) - 1];
    reg [FIFO_AW:0] wp_q, rp_q;
    reg [8:0]       head_q;               // oldest byte, valid with hv_q
    reg             hv_q;
    wire            ram_empty  = (wp_q == rp_q);
    wire            fifo_full  = (wp_q[FIFO_AW] != rp_q[FIFO_AW]) &&
                                 (wp_q[FIFO_AW-1:0] == rp_q[FIFO_AW-1:0]);
    wire            fifo_empty = !hv_q && ram_empty;    // no byte waiting at all
    wire [7:0]      rbyte      = head_q[7:0];
    wire            rferr      = head_q[8];
    wire            pop;
    wire            head_load  = !ram_empty && (!hv_q || pop);

    always @(posedge clk) begin
        if (rx_valid && !fifo_full) fifo_mem[wp_q[FIFO_AW-1:0]] <= {rx_ferr, rx_data};
        if (head_load) head_q <= fifo_mem[rp_q[FIFO_AW-1:0]];
    end

    // ---- request payload buffer -------------------------------------------------------
    reg [7:0]    pbuf [0:PAYLOAD_MAX-1];
    reg [15:0]   pidx_q;              // payload byte index (receive) / read index (WRITE)
    wire [7:0]   pbuf_rd = pbuf[pidx_q[PW-1:0]];
    wire         pbuf_we;

    always @(posedge clk) begin
        if (pbuf_we) pbuf[pidx_q[PW-1:0]] <= rbyte;
    end

    // ---- state ------------------------------------------------------------------------
    reg [4:0]    state_q;
    reg [4:0]    after_q;             // state after the reply
    reg          junk_q;              // bytes seen outside a frame, not yet reported
    reg          ovf_q;               // receive FIFO overflowed
    reg [TW-1:0] tmo_q;               // idle clocks (timer)
    reg [15:0]   len_q;               // request LEN
    reg [7:0]    seq_q;               // request SEQ (0 until received)
    reg [7:0]    cmd_q;               // request CMD (0 until received)
    reg [31:0]   hdr_q;               // first four payload bytes
    reg [7:0]    crch_q;              // received CRC high byte
    reg [15:0]   crc_rx_q;            // running CRC of the request
    reg [15:0]   crc_tx_q;            // running CRC of the reply
    reg [15:0]   tx_len_q;            // reply LEN
    reg [7:0]    tx_seq_q;
    reg [7:0]    tx_cmd_q;
    reg [2:0]    src_q;               // reply payload source
    reg [15:0]   tx_cnt_q;            // reply payload bytes still to send
    reg [1:0]    wbyte_q;             // byte of the current word (0 = first)
    reg [31:0]   word_q;              // current reply word, MSB goes next
    reg [1:0]    iword_q;             // INFO word index
    reg [15:0]   rd_addr_q;           // next register / block address to read
    reg [7:0]    wait_q;              // read latency counter
    reg [7:0]    err_code_q;          // code of the error being replied
    reg [EV_W-1:0] ev_q;              // event being sent
    reg [7:0]    ev_seq_q;            // SEQ of event frames
    reg [23:0]   wacc_q;              // WRITE data being assembled (first three bytes)

    wire in_frame  = (state_q >= S_LENH) && (state_q <= S_CRCL);
    wire parsing   = (state_q <= S_DISCARD);
    assign pop     = parsing && hv_q && !ovf_q;
    wire tmo_run   = fifo_empty && (in_frame || (state_q == S_DISCARD) ||
                                    ((state_q == S_HUNT) && junk_q));
    wire tmo_hit   = tmo_run && ({{(32-TW){1'b0}}, tmo_q} == TMO_LAST);
    wire ev_take   = (state_q == S_HUNT) && fifo_empty && !junk_q && !ovf_q &&
                     stream_en_o && evs_valid_i;
    assign evs_ready_o = ev_take | ~stream_en_o;
    assign pbuf_we = pop && (state_q == S_PAY) && !rferr && (pidx_q < PMAX16);

    wire [15:0] crc_rx_next;
    wire [15:0] crc_tx_next;
    fmt_crc16 u_crc_rx (.crc_i(crc_rx_q), .data_i(rbyte),   .crc_o(crc_rx_next));
    fmt_crc16 u_crc_tx (.crc_i(crc_tx_q), .data_i(tx_data), .crc_o(crc_tx_next));

    // transmit byte of the current state
    always @(*) begin
        tx_valid = 1'b1;
        case (state_q)
            S_TSYNC: tx_data = SYNC;
            S_TLENH: tx_data = tx_len_q[15:8];
            S_TLENL: tx_data = tx_len_q[7:0];
            S_TSEQ:  tx_data = tx_seq_q;
            S_TCMD:  tx_data = tx_cmd_q;
            S_TPAY:  tx_data = word_q[31:24];
            S_TCRCH: tx_data = crc_tx_q[15:8];
            S_TCRCL: tx_data = crc_tx_q[7:0];
            default: begin tx_data = 8'h00; tx_valid = 1'b0; end
        endcase
    end
    wire tx_fire = tx_valid && tx_ready;

    // INFO words (see fmt.protocol.info_payload)
    reg [31:0] info_word;
    always @(*) begin
        case (iword_q)
            2'd0:    info_word = MAGIC;
            2'd1:    info_word = {VERSION, ROWS8, COLS8};
            2'd2:    info_word = {LOG2_N8, HM_W8, BIN_LO8, BIN_STEP8};
            default: info_word = {REGMAP_ID16, PMAX16};
        endcase
    end

    // request checks (valid in S_EXEC)
    wire [15:0] blk_count = hdr_q[15:0];
    wire [7:0]  rd_count  = hdr_q[7:0];
    wire        wr_len_ok = (len_q >= 16'd6) && (len_q[1:0] == 2'b10);

    // start an error reply (and count the error)
    task start_error;
        input [7:0] code;
        input [4:0] after;
        input [7:0] seq;                  // SEQ to echo (0 outside a frame)
        begin
            err_code_q  <= code;
            err_last_o  <= code;
            err_pulse_o <= 1'b1;
            if (err_count_o != 16'hFFFF) err_count_o <= err_count_o + 1'b1;
            tx_len_q    <= 16'd2;
            tx_seq_q    <= seq;
            tx_cmd_q    <= C_ERROR;
            src_q       <= SRC_ERR;
            after_q     <= after;
            state_q     <= S_TSYNC;
        end
    endtask

    // start a good reply to the current request
    task start_reply;
        input [15:0] len;
        input [2:0]  src;
        begin
            tx_len_q <= len;
            tx_seq_q <= seq_q;
            tx_cmd_q <= cmd_q | 8'h80;
            src_q    <= src;
            after_q  <= S_HUNT;
            state_q  <= S_TSYNC;
        end
    endtask

    always @(posedge clk) begin
        if (rst) begin
            wp_q <= {(FIFO_AW+1){1'b0}};
            rp_q <= {(FIFO_AW+1){1'b0}};
            hv_q <= 1'b0;
            state_q <= S_HUNT;
            after_q <= S_HUNT;
            junk_q <= 1'b0;
            ovf_q <= 1'b0;
            tmo_q <= {TW{1'b0}};
            len_q <= 16'd0;
            seq_q <= 8'd0;
            cmd_q <= 8'd0;
            hdr_q <= 32'd0;
            crch_q <= 8'd0;
            crc_rx_q <= 16'hFFFF;
            crc_tx_q <= 16'hFFFF;
            tx_len_q <= 16'd0;
            tx_seq_q <= 8'd0;
            tx_cmd_q <= 8'd0;
            src_q <= SRC_NONE;
            tx_cnt_q <= 16'd0;
            wbyte_q <= 2'd0;
            word_q <= 32'd0;
            iword_q <= 2'd0;
            rd_addr_q <= 16'd0;
            wait_q <= 8'd0;
            err_code_q <= 8'd0;
            ev_q <= {EV_W{1'b0}};
            ev_seq_q <= 8'd0;
            wacc_q <= 24'd0;
            pidx_q <= 16'd0;
            reg_we_o <= 1'b0;
            reg_re_o <= 1'b0;
            reg_addr_o <= 16'd0;
            reg_wdata_o <= 32'd0;
            blk_req_o <= 1'b0;
            blk_addr_o <= 16'd0;
            stream_en_o <= 1'b0;
            err_count_o <= 16'd0;
            err_last_o <= 8'd0;
            err_pulse_o <= 1'b0;
        end else begin
            reg_we_o    <= 1'b0;
            reg_re_o    <= 1'b0;
            blk_req_o   <= 1'b0;
            err_pulse_o <= 1'b0;
            if (rx_valid && !fifo_full) wp_q <= wp_q + 1'b1;
            if (head_load) rp_q <= rp_q + 1'b1;
            if (head_load) hv_q <= 1'b1;
            else if (pop) hv_q <= 1'b0;
            if (pop || !tmo_run) tmo_q <= {TW{1'b0}};
            else if (!tmo_hit) tmo_q <= tmo_q + 1'b1;

            case (state_q)
                // ---- receive ---------------------------------------------------------
                S_HUNT: begin
                    if (ovf_q) begin
                        ovf_q  <= 1'b0;
                        junk_q <= 1'b0;
                        cmd_q  <= 8'd0;
                        start_error(E_OVERFLOW, S_DISCARD, 8'd0);
                    end else if (pop) begin
                        if (rbyte == SYNC && !rferr) begin
                            if (junk_q) begin           // junk right before a frame: count only
                                err_last_o  <= E_JUNK;
                                err_pulse_o <= 1'b1;
                                if (err_count_o != 16'hFFFF) err_count_o <= err_count_o + 1'b1;
                            end
                            junk_q   <= 1'b0;
                            crc_rx_q <= 16'hFFFF;
                            seq_q    <= 8'd0;
                            cmd_q    <= 8'd0;
                            state_q  <= S_LENH;
                        end else begin
                            junk_q <= 1'b1;
                        end
                    end else if (tmo_hit) begin         // junk burst ended by an idle line
                        junk_q <= 1'b0;
                        cmd_q  <= 8'd0;
                        start_error(E_JUNK, S_HUNT, 8'd0);
                    end else if (ev_take) begin
                        ev_q     <= evs_data_i;
                        ev_seq_q <= ev_seq_q + 1'b1;
                        tx_len_q <= EVLEN16;
                        tx_seq_q <= ev_seq_q;
                        tx_cmd_q <= C_EVENT;
                        src_q    <= SRC_EVT;
                        after_q  <= S_HUNT;
                        state_q  <= S_TSYNC;
                    end
                end
                S_LENH, S_LENL, S_SEQ, S_CMD, S_PAY, S_CRCH, S_CRCL: begin
                    if (ovf_q) begin
                        ovf_q <= 1'b0;
                        start_error(E_OVERFLOW, S_DISCARD, seq_q);
                    end else if (pop && rferr) begin
                        start_error(E_FRAMING, S_DISCARD, seq_q);
                    end else if (pop) begin
                        if (state_q <= S_PAY) crc_rx_q <= crc_rx_next;
                        case (state_q)
                            S_LENH: begin len_q[15:8] <= rbyte; state_q <= S_LENL; end
                            S_LENL: begin len_q[7:0]  <= rbyte; state_q <= S_SEQ;  end
                            S_SEQ:  begin seq_q <= rbyte; state_q <= S_CMD; end
                            S_CMD: begin
                                cmd_q  <= rbyte;
                                pidx_q <= 16'd0;
                                hdr_q  <= 32'd0;
                                if (len_q > PMAX16) begin
                                    start_error(E_LEN, S_DISCARD, seq_q);
                                end else if (len_q == 16'd0) begin
                                    state_q <= S_CRCH;
                                end else begin
                                    state_q <= S_PAY;
                                end
                            end
                            S_PAY: begin
                                if (pidx_q < 16'd4) hdr_q <= {hdr_q[23:0], rbyte};
                                pidx_q <= pidx_q + 1'b1;
                                if (pidx_q == len_q - 1'b1) state_q <= S_CRCH;
                            end
                            S_CRCH: begin crch_q <= rbyte; state_q <= S_CRCL; end
                            default: begin              // S_CRCL
                                if ({crch_q, rbyte} != crc_rx_q) start_error(E_CRC, S_HUNT, seq_q);
                                else state_q <= S_EXEC;
                            end
                        endcase
                    end else if (tmo_hit) begin
                        start_error(E_TIMEOUT, S_HUNT, seq_q);
                    end
                end
                S_DISCARD: begin
                    if (ovf_q) ovf_q <= 1'b0;
                    else if (tmo_hit) state_q <= S_HUNT;
                end
                // ---- execute ---------------------------------------------------------
                S_EXEC: begin
                    case (cmd_q)
                        C_INFO: begin
                            if (len_q == 16'd0) begin
                                iword_q <= 2'd0;
                                start_reply(16'd16, SRC_INFO);
                            end else start_error(E_LEN, S_HUNT, seq_q);
                        end
                        C_READ: begin
                            if (len_q == 16'd3 && rd_count != 8'd0) begin
                                rd_addr_q <= hdr_q[23:8];
                                start_reply({6'd0, rd_count, 2'b00}, SRC_REG);
                            end else start_error(E_LEN, S_HUNT, seq_q);
                        end
                        C_BLKREAD: begin
                            if (len_q == 16'd4 && blk_count != 16'd0 && blk_count[15:14] == 2'b00) begin
                                rd_addr_q <= hdr_q[31:16];
                                start_reply({blk_count[13:0], 2'b00}, SRC_BLK);
                            end else start_error(E_LEN, S_HUNT, seq_q);
                        end
                        C_WRITE: begin
                            if (wr_len_ok) begin
                                rd_addr_q <= hdr_q[31:16];   // write address
                                pidx_q    <= 16'd2;
                                state_q   <= S_WR;
                            end else start_error(E_LEN, S_HUNT, seq_q);
                        end
                        C_STREAM: begin
                            if (len_q == 16'd1) begin
                                stream_en_o <= hdr_q[0];
                                start_reply(16'd0, SRC_NONE);
                            end else start_error(E_LEN, S_HUNT, seq_q);
                        end
                        default: start_error(E_CMD, S_HUNT, seq_q);
                    endcase
                end
                S_WR: begin                             // one payload byte per cycle
                    wacc_q <= {wacc_q[15:0], pbuf_rd};
                    pidx_q <= pidx_q + 1'b1;
                    if (pidx_q[1:0] == 2'b01) begin     // bytes 2..5, 6..9, ...: word complete
                        reg_we_o    <= 1'b1;
                        reg_addr_o  <= rd_addr_q;
                        reg_wdata_o <= {wacc_q, pbuf_rd};
                        rd_addr_q   <= rd_addr_q + 1'b1;
                    end
                    if (pidx_q == len_q - 1'b1) start_reply(16'd0, SRC_NONE);
                end
                // ---- transmit --------------------------------------------------------
                S_TSYNC: if (tx_fire) begin crc_tx_q <= 16'hFFFF; state_q <= S_TLENH; end
                S_TLENH: if (tx_fire) begin crc_tx_q <= crc_tx_next; state_q <= S_TLENL; end
                S_TLENL: if (tx_fire) begin crc_tx_q <= crc_tx_next; state_q <= S_TSEQ; end
                S_TSEQ:  if (tx_fire) begin crc_tx_q <= crc_tx_next; state_q <= S_TCMD; end
                S_TCMD: if (tx_fire) begin
                    crc_tx_q <= crc_tx_next;
                    tx_cnt_q <= tx_len_q;
                    state_q  <= (tx_len_q == 16'd0) ? S_TCRCH : S_TFETCH;
                end
                S_TFETCH: begin
                    wbyte_q <= 2'd0;
                    case (src_q)
                        SRC_REG: begin
                            reg_re_o   <= 1'b1;
                            reg_addr_o <= rd_addr_q;
                            rd_addr_q  <= rd_addr_q + 1'b1;
                            wait_q     <= 8'd1;
                            state_q    <= S_TWAIT;
                        end
                        SRC_BLK: begin
                            blk_req_o  <= 1'b1;
                            blk_addr_o <= rd_addr_q;
                            rd_addr_q  <= rd_addr_q + 1'b1;
                            wait_q     <= BLK_LAT8;
                            state_q    <= S_TWAIT;
                        end
                        SRC_INFO: begin
                            word_q  <= info_word;
                            iword_q <= iword_q + 1'b1;
                            state_q <= S_TPAY;
                        end
                        SRC_EVT: begin
                            word_q  <= ev_q[EV_W-1 -: 32];
                            ev_q    <= ev_q << 32;
                            state_q <= S_TPAY;
                        end
                        default: begin                  // SRC_ERR
                            word_q  <= {err_code_q, cmd_q, 16'h0000};
                            state_q <= S_TPAY;
                        end
                    endcase
                end
                S_TWAIT: begin
                    if (wait_q != 8'd0) begin
                        wait_q <= wait_q - 1'b1;
                    end else begin
                        word_q  <= (src_q == SRC_BLK) ? blk_rdata_i : reg_rdata_i;
                        state_q <= S_TPAY;
                    end
                end
                S_TPAY: if (tx_fire) begin
                    crc_tx_q <= crc_tx_next;
                    word_q   <= {word_q[23:0], 8'h00};
                    wbyte_q  <= wbyte_q + 1'b1;
                    tx_cnt_q <= tx_cnt_q - 1'b1;
                    if (tx_cnt_q == 16'd1) state_q <= S_TCRCH;
                    else if (wbyte_q == 2'd3) state_q <= S_TFETCH;
                end
                S_TCRCH: if (tx_fire) state_q <= S_TCRCL;
                S_TCRCL: if (tx_fire) state_q <= after_q;
                default: state_q <= S_HUNT;
            endcase

            if (rx_valid && fifo_full) ovf_q <= 1'b1;   // wins over a clear in the same cycle
        end
    end

`ifdef FORMAL
    // Formal properties (SymbiYosys, formal/fmt_ctrl_port.sby; never seen by synthesis).
    // The UART receiver and transmitter are replaced by free stand-ins (formal/stubs), so
    // the parser is proved for any byte stream and any transmit pacing.  A shadow built
    // only from the bytes the parser consumes (its own bit-serial CRC, LEN, CMD and the
    // payload) states the promises: nothing executes before its frame's CRC was checked;
    // a register write is a word of a good WRITE frame at its address; every error is
    // counted (saturating); a frame or a discard left without bytes times out, so the
    // parser always resynchronises; the WRITE never reads past the buffered payload.
    localparam F_PB = PAYLOAD_MAX * 8;
    reg          f_rstd_q = 1'b0;                 // a reset has been applied
    reg  [15:0]  f_crc_q;                         // CRC of LEN..PAYLOAD as consumed
    reg  [15:0]  f_len_q;
    reg  [7:0]   f_cmd_q;
    reg  [7:0]   f_crch_q;
    reg  [F_PB-1:0] f_pay_q;                      // payload bytes, byte i at [8i +: 8]
    reg  [15:0]  f_n_q;                           // payload bytes consumed
    reg          f_good_q;                        // the frame's CRC matched the shadow's
    reg  [15:0]  f_k_q;                           // register writes of this frame
    reg  [7:0]   f_idle_q;                        // clocks without a byte while parsing
    reg  [15:0]  f_cnt_q;                         // err_count_o a cycle ago
    reg          f_tsync_q;                       // state_q was S_TSYNC a cycle ago
    integer      fb;
    reg  [15:0]  f_crc_d;
    wire         f_byte   = pop && !rferr;        // a byte the frame takes
    wire         f_pstate = (state_q <= S_DISCARD) && !(state_q == S_HUNT && !junk_q);
    always @(*) begin                             // one CRC step, bit by bit
        f_crc_d = f_crc_q;
        for (fb = 7; fb >= 0; fb = fb - 1)
            f_crc_d = {f_crc_d[14:0], 1'b0} ^ ({16{f_crc_d[15] ^ rbyte[fb]}} & 16'h1021);
    end
    always @(posedge clk) begin
        f_rstd_q  <= f_rstd_q | rst;
        f_cnt_q   <= err_count_o;
        f_tsync_q <= (state_q == S_TSYNC);
        if (rst || !f_pstate || rx_valid) f_idle_q <= 8'd0;
        else if (f_idle_q != 8'hFF)       f_idle_q <= f_idle_q + 1'b1;
        if (state_q == S_HUNT) begin
            f_good_q <= 1'b0;
            if (f_byte && rbyte == SYNC) f_crc_q <= 16'hFFFF;
        end
        if (f_byte && state_q >= S_LENH && state_q <= S_PAY) f_crc_q <= f_crc_d;
        if (f_byte && state_q == S_LENH) f_len_q[15:8] <= rbyte;
        if (f_byte && state_q == S_LENL) f_len_q[7:0]  <= rbyte;
        if (f_byte && state_q == S_CMD) begin f_cmd_q <= rbyte; f_n_q <= 16'd0; end
        if (f_byte && state_q == S_PAY) begin
            if (f_n_q < PAYLOAD_MAX) f_pay_q[8 * f_n_q +: 8] <= rbyte;
            f_n_q <= f_n_q + 1'b1;
        end
        if (f_byte && state_q == S_CRCH) f_crch_q <= rbyte;
        if (f_byte && state_q == S_CRCL) f_good_q <= ({f_crch_q, rbyte} == f_crc_q);
        if (state_q == S_EXEC) f_k_q <= 16'd0;
        else if (reg_we_o)     f_k_q <= f_k_q + 1'b1;
    end
    integer fi;
    wire [FIFO_AW:0] f_used = wp_q - rp_q;        // bytes in the FIFO's RAM
    wire [15:0]  f_h = (f_n_q < 16'd4) ? f_n_q : 16'd4;   // payload bytes in hdr_q
    always @(*) begin
        if (f_rstd_q && !rst) begin
            // only the defined states
            assert (state_q <= S_WR || (state_q >= S_TSYNC && state_q <= S_TCRCL));
            // the parser's running CRC, LEN and payload are those of the bytes consumed
            if (state_q >= S_LENH && state_q <= S_CRCL) assert (crc_rx_q == f_crc_q);
            if ((state_q >= S_SEQ && state_q <= S_CRCL) || state_q == S_EXEC || state_q == S_WR)
                assert (len_q == f_len_q);
            if (state_q == S_PAY) assert (pidx_q == f_n_q && f_n_q < len_q && len_q <= PMAX16);
            if (state_q >= S_PAY && state_q <= S_CRCL) assert (cmd_q == f_cmd_q);
            // the header holds the first (up to four) payload bytes
            if ((state_q >= S_PAY && state_q <= S_CRCL) || state_q == S_EXEC)
                for (fi = 0; fi < 4; fi = fi + 1)
                    if (fi < f_h) assert (hdr_q[8 * (f_h - 1 - fi) +: 8] == f_pay_q[8 * fi +: 8]);
            if (state_q == S_CRCH || state_q == S_CRCL) assert (f_n_q == len_q && len_q <= PMAX16);
            assert (after_q == S_HUNT || after_q == S_DISCARD);
            if (state_q == S_PAY || state_q == S_CRCH || state_q == S_CRCL || state_q == S_EXEC ||
                state_q == S_WR)
                for (fi = 0; fi < PAYLOAD_MAX; fi = fi + 1)
                    if (fi < f_n_q) assert (pbuf[fi] == f_pay_q[8 * fi +: 8]);
            // nothing executes before its frame's CRC has been checked
            if (state_q == S_EXEC || state_q == S_WR)
                assert (f_good_q && cmd_q == f_cmd_q && f_n_q == len_q && len_q <= PMAX16);
            // the WRITE reads only buffered payload bytes, one word per 4
            if (state_q == S_WR) begin
                assert (cmd_q == C_WRITE && wr_len_ok);
                assert (pidx_q >= 16'd2 && pidx_q < len_q);
                // words issued: (pidx - 2) / 4, the last one on reg_we_o now
                assert (f_k_q + (reg_we_o ? 16'd1 : 16'd0) == ((pidx_q - 16'd2) >> 2));
                assert (rd_addr_q == {f_pay_q[7:0], f_pay_q[15:8]} + ((pidx_q - 16'd2) >> 2));
                // the word being assembled: the bytes read since the last word
                for (fi = 1; fi <= 3; fi = fi + 1)
                    if (((pidx_q - 16'd2) & 16'd3) >= fi)
                        assert (wacc_q[8 * (fi - 1) +: 8] == f_pay_q[8 * (pidx_q - fi) +: 8]);
            end
            // a register write is the k-th word of a good WRITE frame, at ADDR + k
            if (reg_we_o) begin
                assert (f_good_q && f_cmd_q == C_WRITE);
                assert (reg_addr_o == {f_pay_q[7:0], f_pay_q[15:8]} + f_k_q);
                assert (reg_wdata_o == {f_pay_q[8 * (4 * f_k_q + 2) +: 8],
                                        f_pay_q[8 * (4 * f_k_q + 3) +: 8],
                                        f_pay_q[8 * (4 * f_k_q + 4) +: 8],
                                        f_pay_q[8 * (4 * f_k_q + 5) +: 8]});
            end
            // resynchronisation: inside a frame, a discard or a junk burst, the port
            // never waits longer than the timeout after the last byte (plus the bytes
            // still queued: the FIFO, its head and the one being written)
            assert (tmo_q <= TMO_LAST);
            if (junk_q) assert (state_q == S_HUNT);      // junk is only seen between frames
            assert (f_used <= (1 << FIFO_AW));           // the FIFO holds at most its depth
            if (tmo_run) assert (tmo_q <= f_idle_q);
            assert (f_idle_q <= TMO_CLKS + (1 << FIFO_AW) + 2);
        end
    end
    always @(posedge clk) begin
        if (f_rstd_q && !rst && !$past(rst)) begin
            // every error is counted, saturating, never wrapped
            // (err_pulse_o and the count are loaded at the same edge)
            if (err_pulse_o && f_cnt_q != 16'hFFFF) assert (err_count_o == f_cnt_q + 1'b1);
            else                                    assert (err_count_o == f_cnt_q);
            // every error reply starts with its count
            if (state_q == S_TSYNC && !f_tsync_q && tx_cmd_q == C_ERROR) assert (err_pulse_o);
        end
    end
`endif

endmodule
`default_nettype wire
