// RMII transmitter for replies: preamble, SFD, Ethernet header (to dst_mac, from
// SOURCE_MAC, EtherType), the reply buffer zero-padded to the 46-byte minimum payload, the
// FCS (complemented CRC-32, least significant byte first), then a 12-byte inter-frame gap.
module rmii_tx #(
    parameter [47:0] SOURCE_MAC = 48'h02695A065491,
    parameter [15:0] ETHERTYPE = 16'h88B5
) (
    input  wire        clk,
    input  wire        rst,
    input  wire        start,
    input  wire [5:0]  len,
    input  wire [47:0] dst_mac,
    output wire [5:0]  idx,
    input  wire [7:0]  buf_byte,
    output wire        busy,
    output reg         tx_en,
    output reg  [1:0]  txd
);
`include "crc32.vh"

    reg        active;
    reg [6:0]  pos;        // byte position: 0-7 preamble/SFD, 8.. frame, then FCS and gap
    reg [1:0]  dibit;
    reg [7:0]  cur;
    reg [31:0] crc;
    reg [5:0]  n;
    reg [47:0] dst;
    wire [6:0] fcs_at = 7'd8 + 7'd14 + ((n < 46) ? 7'd46 : {1'b0, n});  // first FCS byte
    assign idx = pos - 7'd22;
    assign busy = active;

    // the byte at frame position p (valid for p < fcs_at)
    function [7:0] frame_at;
        input [6:0] p;
        begin
            if (p < 7) frame_at = 8'h55;
            else if (p == 7) frame_at = 8'hD5;
            else if (p < 14) frame_at = dst[8 * (13 - p) +: 8];
            else if (p < 20) frame_at = SOURCE_MAC[8 * (19 - p) +: 8];
            else if (p == 20) frame_at = ETHERTYPE[15:8];
            else if (p == 21) frame_at = ETHERTYPE[7:0];
            else if (p - 22 < n) frame_at = buf_byte;
            else frame_at = 8'h00;
        end
    endfunction

    always @(posedge clk) begin
        if (rst) begin
            active <= 1'b0;
            tx_en <= 1'b0;
            txd <= 2'b00;
        end else if (!active) begin
            tx_en <= 1'b0;
            txd <= 2'b00;
            if (start) begin
                active <= 1'b1;
                n <= len;
                dst <= dst_mac;
                pos <= 0;
                dibit <= 0;
                crc <= 32'hFFFFFFFF;
            end
        end else begin
            if (dibit == 0) begin  // load the next byte
                if (pos < fcs_at) begin
                    cur = frame_at(pos);
                    if (pos >= 8) crc <= crc32_byte(crc, cur);
                end else begin
                    cur = ~crc[8 * (pos - fcs_at) +: 8];
                end
                tx_en <= (pos < fcs_at + 4);
                txd <= (pos < fcs_at + 4) ? cur[1:0] : 2'b00;
            end else begin
                tx_en <= (pos < fcs_at + 4);
                txd <= (pos < fcs_at + 4) ? cur[2 * dibit +: 2] : 2'b00;
            end
            dibit <= dibit + 1'b1;
            if (dibit == 3) begin
                pos <= pos + 1'b1;
                if (pos == fcs_at + 4 + 12 - 1) active <= 1'b0;
            end
        end
    end
endmodule
