// The device side of the REND3R load protocol (docs/protocol.md): checks each frame
// (length, CRC-32, version), stages BEGIN/DATA/COMMIT loads in the inactive bank of
// program_memory, swaps banks on a COMMIT whose length and CRC-32 match the staged words,
// handles RUN/STOP/RESET/STATUS, and builds exactly one ACK or NACK per well-formed request
// in a reply buffer that a link transmitter reads (reply_idx -> reply_byte).
//
// Input: one byte stream (in_first marks a frame's first byte, in_last ends the frame;
// bytes after the frame's CRC, like Ethernet padding and FCS, are ignored). A frame that
// starts while the engine is still answering the previous one is dropped whole.
module rend3r_engine #(
    parameter AW = 10,                 // log2 of the words per bank
    parameter [31:0] MAX_WORDS = 1 << AW
) (
    input  wire          clk,
    input  wire          rst,
    input  wire          in_valid,
    input  wire [7:0]    in_data,
    input  wire          in_first,
    input  wire          in_last,
    input  wire          in_err,
    // program_memory port A
    output reg           mem_we,
    output reg  [AW:0]   mem_addr,
    output reg  [31:0]   mem_wdata,
    input  wire [31:0]   mem_rdata,
    output reg           bank,          // active bank; staging is ~bank
    // reply buffer
    output reg           reply_start,   // pulse: reply_len bytes ready in the buffer
    output reg  [5:0]    reply_len,
    input  wire [5:0]    reply_idx,
    output wire [7:0]    reply_byte,
    input  wire          reply_busy,    // the transmitter still reads the previous reply
    // instruction processor
    input  wire [31:0]   frames_rendered,
    output reg           running,
    output reg           restart,       // pulse: (re)start the active program at address 0
    output wire          accepting,     // a frame starting now is taken
    // status
    output reg  [31:0]   active_words,
    output reg  [31:0]   active_crc,
    output reg  [15:0]   active_load,
    output reg  [31:0]   malformed,
    output reg  [31:0]   loads
);
`include "crc32.vh"

    localparam [7:0] T_BEGIN = 8'h01, T_DATA = 8'h02, T_COMMIT = 8'h03, T_RUN = 8'h04,
                     T_STOP = 8'h05, T_RESET = 8'h06, T_STATUS = 8'h07,
                     T_ACK = 8'h80, T_NACK = 8'h81;
    localparam [7:0] N_VERSION = 1, N_TYPE = 2, N_FIELDS = 3, N_NO_LOAD = 4,
                     N_RANGE = 5, N_MISMATCH = 6, N_TOO_LARGE = 7;
    localparam [AW-1:0] FOUR = 4;         // header words before the payload
    localparam [2:0] S_RX = 0, S_DECIDE = 1, S_VERIFY = 2, S_CLEAR = 3, S_REPLY = 4;

    reg [2:0]  state;
    reg        receiving;               // bytes of an accepted frame are arriving
    reg        dropping;                // a frame started while busy: ignore until its end
    reg [15:0] idx;                     // bytes received in this frame (saturating)
    reg [7:0]  hdr [0:15];
    reg [31:0] crc;                     // running CRC over header and payload
    reg [31:0] rx_crc;                  // the frame's CRC field
    reg [63:0] info;                    // BEGIN/COMMIT payload: words, program CRC
    reg [23:0] part;                    // payload bytes of the word being assembled

    // staging
    reg        staging;
    reg [15:0] st_load;
    reg [31:0] st_words;
    reg [31:0] st_crc;

    // header fields
    wire [7:0]  f_version = hdr[0];
    wire [7:0]  f_type    = hdr[1];
    wire [15:0] f_load    = {hdr[2], hdr[3]};
    wire [15:0] f_count   = {hdr[6], hdr[7]};
    wire [31:0] f_offset  = {hdr[8], hdr[9], hdr[10], hdr[11]};
    wire [15:0] f_length  = {hdr[12], hdr[13]};
    wire [16:0] body_end  = 17'd16 + f_length;
    wire [31:0] i_words   = info[63:32];
    wire [31:0] i_crc     = info[31:0];

    wire data_fields_ok = f_count >= 1 && f_count <= 256 && {2'b00, f_length} == {f_count, 2'b00};
    wire info_fields_ok = f_count == 0 && f_offset == 0 && f_length == 8;
    wire ctrl_fields_ok = f_count == 0 && f_offset == 0 && f_length == 0;
    wire [32:0] data_end = {1'b0, f_offset} + {17'd0, f_count};
    wire data_in_range  = data_end <= {1'b0, st_words};
    // DATA of the open load: its payload streams straight into staging (protocol.md step 3)
    wire data_writes = f_version == 1 && f_type == T_DATA && data_fields_ok && staging &&
                       f_load == st_load && data_in_range;

    // reply
    reg [7:0]  rep_type, rep_code;
    reg [4:0]  rep_plen;                // 0, 4 (TOO_LARGE) or 24 (STATUS)
    reg [7:0]  txbuf [0:43];
    reg [5:0]  build;                   // next reply byte to build
    reg [31:0] tx_crc;
    assign reply_byte = txbuf[reply_idx];
    assign accepting = (state == S_RX);

    // verify / clear loop
    reg [AW:0] walk;                    // next word address to read or clear
    reg [1:0]  pending;                 // staging reads in flight (the RAM has 2 cycles' latency)
    reg [31:0] vcrc;
    wire [31:0] walk32 = {{(31 - AW){1'b0}}, walk};

    wire [191:0] status_bytes = {active_words, active_crc, frames_rendered, 7'd0, running,
                                 7'd0, staging, active_load, malformed, loads};

    function [7:0] reply_at;
        input [5:0] i;
        begin
            case (i)
                0: reply_at = 8'h01;
                1: reply_at = rep_type;
                12: reply_at = 8'h00;
                13: reply_at = {3'd0, rep_plen};
                14: reply_at = f_type;
                15: reply_at = rep_code;
                default:
                    if (i < 12) reply_at = hdr[i[3:0]];  // load, seq, count, offset of the request
                    else if (rep_plen == 4) reply_at = MAX_WORDS[8 * (19 - i) +: 8];
                    else reply_at = status_bytes[8 * (39 - i) +: 8];
            endcase
        end
    endfunction

    task reply;
        input [7:0] t;
        input [7:0] code;
        input [4:0] plen;
        begin
            rep_type <= t;
            rep_code <= code;
            rep_plen <= plen;
            build <= 0;
            tx_crc <= 32'hFFFFFFFF;
            state <= S_REPLY;
        end
    endtask

    integer k;
    always @(posedge clk) begin
        mem_we <= 1'b0;
        reply_start <= 1'b0;
        restart <= 1'b0;
        if (rst) begin
            state <= S_RX;
            receiving <= 1'b0;
            dropping <= 1'b0;
            staging <= 1'b0;
            bank <= 1'b0;
            running <= 1'b1;
            active_words <= 0;
            active_crc <= 0;
            active_load <= 0;
            malformed <= 0;
            loads <= 0;
            reply_len <= 0;
            for (k = 0; k < 16; k = k + 1) hdr[k] <= 8'd0;
        end else begin
            // ---- byte intake (only in S_RX; frames starting while busy are dropped) ----
            if (in_valid && in_first) begin
                receiving <= (state == S_RX);
                dropping <= (state != S_RX);
            end
            if (in_valid && state == S_RX && (in_first || receiving)) begin
                idx <= in_first ? 16'd1 : (idx == 16'hFFFF ? idx : idx + 1'b1);
                if (in_first) begin
                    hdr[0] <= in_data;
                    crc <= crc32_byte(32'hFFFFFFFF, in_data);
                end else if (idx < 16) begin
                    hdr[idx[3:0]] <= in_data;
                    crc <= crc32_byte(crc, in_data);
                end else if ({1'b0, idx} < body_end) begin
                    crc <= crc32_byte(crc, in_data);
                    info <= {info[55:0], in_data};
                    part <= {part[15:0], in_data};
                    if (data_writes && idx[1:0] == 2'd3) begin
                        mem_we <= 1'b1;
                        mem_addr <= {~bank, f_offset[AW-1:0] + idx[AW+1:2] - FOUR};
                        mem_wdata <= {part, in_data};
                    end
                end else if ({1'b0, idx} < body_end + 17'd4) begin
                    rx_crc <= {rx_crc[23:0], in_data};
                end
            end
            if (in_last) begin
                dropping <= 1'b0;
                if (state == S_RX && receiving) begin
                    receiving <= 1'b0;
                    if (in_err || idx < 20 || {1'b0, idx} < body_end + 17'd4 || ~crc != rx_crc)
                        malformed <= malformed + 1'b1;
                    else
                        state <= S_DECIDE;
                end else if (state == S_RX && !dropping && in_err) begin
                    malformed <= malformed + 1'b1;  // garbage that decoded to nothing
                end
            end

            case (state)
            S_DECIDE: begin
                if (f_version != 1) reply(T_NACK, N_VERSION, 0);
                else case (f_type)
                T_ACK, T_NACK: state <= S_RX;  // replies sent to the device: ignored
                T_BEGIN:
                    if (!info_fields_ok) reply(T_NACK, N_FIELDS, 0);
                    else if (i_words > MAX_WORDS) reply(T_NACK, N_TOO_LARGE, 4);
                    else if (staging && st_load == f_load && st_words == i_words && st_crc == i_crc)
                        reply(T_ACK, 0, 0);  // repeated BEGIN keeps the staged words
                    else if (!staging && active_load == f_load && active_words == i_words &&
                             active_crc == i_crc)
                        reply(T_ACK, 0, 0);  // late duplicate of the committed load
                    else begin
                        staging <= 1'b1;
                        st_load <= f_load;
                        st_words <= i_words;
                        st_crc <= i_crc;
                        reply(T_ACK, 0, 0);
                    end
                T_DATA:
                    if (!data_fields_ok) reply(T_NACK, N_FIELDS, 0);
                    else if (!staging || st_load != f_load)
                        reply((!staging && f_load == active_load && active_load != 0) ? T_ACK : T_NACK,
                              (!staging && f_load == active_load && active_load != 0) ? 8'd0 : N_NO_LOAD, 0);
                    else if (!data_in_range) reply(T_NACK, N_RANGE, 0);
                    else reply(T_ACK, 0, 0);
                T_COMMIT:
                    if (!info_fields_ok) reply(T_NACK, N_FIELDS, 0);
                    else if (!staging || st_load != f_load)
                        reply((active_load == f_load && active_words == i_words && active_crc == i_crc)
                              ? T_ACK : T_NACK,
                              (active_load == f_load && active_words == i_words && active_crc == i_crc)
                              ? 8'd0 : N_NO_LOAD, 0);
                    else if (st_words != i_words || st_crc != i_crc) reply(T_NACK, N_MISMATCH, 0);
                    else begin
                        walk <= 0;
                        pending <= 2'b00;
                        vcrc <= 32'hFFFFFFFF;
                        state <= S_VERIFY;
                    end
                T_RUN, T_STOP, T_RESET, T_STATUS:
                    if (!ctrl_fields_ok) reply(T_NACK, N_FIELDS, 0);
                    else if (f_type == T_RUN) begin
                        running <= 1'b1;
                        restart <= 1'b1;
                        reply(T_ACK, 0, 0);
                    end else if (f_type == T_STOP) begin
                        running <= 1'b0;
                        reply(T_ACK, 0, 0);
                    end else if (f_type == T_RESET) begin
                        staging <= 1'b0;
                        running <= 1'b1;
                        active_words <= 0;
                        active_crc <= 0;
                        active_load <= 0;
                        malformed <= 0;
                        loads <= 0;
                        walk <= 0;
                        state <= S_CLEAR;
                    end else reply(T_ACK, 0, 24);
                default: reply(T_NACK, N_TYPE, 0);
                endcase
            end

            S_VERIFY: begin  // CRC-32 over staging words 0..N-1, one word per cycle
                pending <= {pending[0], walk32 < st_words};
                if (walk32 < st_words) begin
                    mem_addr <= {~bank, walk[AW-1:0]};
                    walk <= walk + 1'b1;
                end
                if (pending[1]) vcrc <= crc32_word(vcrc, mem_rdata);
                if (pending == 2'b00 && walk32 >= st_words) begin
                    if (~vcrc == st_crc) begin
                        bank <= ~bank;
                        staging <= 1'b0;
                        active_words <= st_words;
                        active_crc <= st_crc;
                        active_load <= st_load;
                        loads <= loads + 1'b1;
                        restart <= running;
                        reply(T_ACK, 0, 0);
                    end else reply(T_NACK, N_MISMATCH, 0);
                end
            end

            S_CLEAR: begin  // RESET: zero the standby bank, then make it the active one
                mem_we <= 1'b1;
                mem_addr <= {~bank, walk[AW-1:0]};
                mem_wdata <= 32'd0;
                walk <= walk + 1'b1;
                if (walk == (1 << AW) - 1) begin
                    bank <= ~bank;
                    restart <= 1'b1;
                    reply(T_ACK, 0, 0);
                end
            end

            S_REPLY: if (!reply_busy) begin  // header, payload and CRC into the buffer
                build <= build + 1'b1;
                if (build < 16 + rep_plen) begin
                    txbuf[build] <= reply_at(build);
                    tx_crc <= crc32_byte(tx_crc, reply_at(build));
                end else if (build < 20 + rep_plen) begin
                    txbuf[build] <= ~tx_crc[8 * (3 - (build - 16 - rep_plen)) +: 8];
                end else begin
                    reply_len <= 20 + rep_plen;
                    reply_start <= 1'b1;
                    state <= S_RX;
                end
            end
            default: ;
            endcase
        end
    end
endmodule
