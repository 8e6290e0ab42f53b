// RMII receiver (50 MHz reference clock, 2 bits per clock, earlier bit in rxd[0]).
// Finds preamble and SFD, filters the destination MAC (DEVICE_MAC or broadcast) and the
// EtherType, checks the FCS (CRC-32 register residue 32'hDEBB20E3, the bit-reversed
// complement of the original design's 0x38FB2284) and passes the bytes after the 14-byte
// Ethernet header (protocol frame, padding, FCS) on. Frames for other addresses or
// EtherTypes produce no output; a bad FCS or a frame ending mid-byte ends with err.
// src_mac holds the source address of the last frame passed on (where to answer).
module rmii_rx #(
    parameter [47:0] DEVICE_MAC = 48'h69695A065491,
    parameter [15:0] ETHERTYPE = 16'h88B5
) (
    input  wire        clk,
    input  wire        rst,
    input  wire        crs_dv,
    input  wire [1:0]  rxd,
    output reg         out_valid,
    output reg  [7:0]  out_data,
    output reg         out_first,
    output reg         out_last,
    output reg         out_err,
    output reg  [47:0] src_mac
);
`include "crc32.vh"

    localparam [1:0] S_HUNT = 0, S_PREAMBLE = 1, S_DATA = 2;
    reg [1:0]  state;
    reg [1:0]  dibit;      // dibits of the current byte already shifted in
    reg [5:0]  shift;      // upper six bits of the byte being shifted in
    reg [10:0] count;      // bytes of the frame so far (saturating)
    reg [31:0] fcs;
    reg        dst_ok, bcast, pass;
    reg [47:0] src;
    reg [7:0]  type_hi;
    wire [7:0] byte_in = {rxd, shift};

    always @(posedge clk) begin
        out_valid <= 1'b0;
        out_first <= 1'b0;
        out_last <= 1'b0;
        out_err <= 1'b0;
        if (rst) begin
            state <= S_HUNT;
        end else case (state)
        S_HUNT:
            if (crs_dv && rxd == 2'b01) state <= S_PREAMBLE;
        S_PREAMBLE:
            if (!crs_dv) state <= S_HUNT;
            else if (rxd == 2'b11) begin  // last dibit of the SFD 0xD5
                state <= S_DATA;
                dibit <= 0;
                count <= 0;
                fcs <= 32'hFFFFFFFF;
                dst_ok <= 1'b1;
                bcast <= 1'b1;
                pass <= 1'b0;
            end else if (rxd != 2'b01 && rxd != 2'b00) state <= S_HUNT;
        S_DATA:
            if (!crs_dv && !dibit[0]) begin  // carrier gone (at a nibble boundary)
                state <= S_HUNT;
                if (pass) begin
                    out_last <= 1'b1;
                    out_err <= (dibit != 0) || fcs != 32'hDEBB20E3;
                end
            end else begin
                shift <= byte_in[7:2];
                dibit <= dibit + 1'b1;
                if (dibit == 2'd3) begin
                    fcs <= crc32_byte(fcs, byte_in);
                    if (count != 11'h7FF) count <= count + 1'b1;
                    if (count < 6) begin
                        if (byte_in != DEVICE_MAC[8 * (5 - count) +: 8]) dst_ok <= 1'b0;
                        if (byte_in != 8'hFF) bcast <= 1'b0;
                    end else if (count < 12) begin
                        src <= {src[39:0], byte_in};
                    end else if (count == 12) begin
                        type_hi <= byte_in;
                    end else if (count == 13) begin
                        pass <= (dst_ok || bcast) && {type_hi, byte_in} == ETHERTYPE;
                        if ((dst_ok || bcast) && {type_hi, byte_in} == ETHERTYPE) src_mac <= src;
                    end else if (pass) begin
                        out_valid <= 1'b1;
                        out_data <= byte_in;
                        out_first <= (count == 14);
                    end
                end
            end
        default: state <= S_HUNT;
        endcase
    end
endmodule
