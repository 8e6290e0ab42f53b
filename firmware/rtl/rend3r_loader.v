// Top of the loader: RMII and UART receive paths into one protocol engine, the two-bank
// program memory, and the reply transmitters (a reply leaves on the link its request came
// in on). All logic runs on the 50 MHz RMII reference clock; the instruction processor
// reads the active bank through port B (prog_clk, prog_addr -> prog_data).
module rend3r_loader #(
    parameter AW = 10,
    parameter CLKS_PER_BIT = 434,                  // 50 MHz / 115200 baud
    parameter [47:0] DEVICE_MAC = 48'h69695A065491,
    parameter [47:0] SOURCE_MAC = 48'h02695A065491,
    parameter [15:0] ETHERTYPE = 16'h88B5,
    parameter INIT_FILE = ""
) (
    input  wire          clk,
    input  wire          rst,
    // RMII (LAN8720)
    input  wire          rmii_crs_dv,
    input  wire [1:0]    rmii_rxd,
    output wire          rmii_tx_en,
    output wire [1:0]    rmii_txd,
    // UART
    input  wire          uart_rx,
    output wire          uart_tx,
    // instruction processor
    input  wire          prog_clk,
    input  wire [AW-1:0] prog_addr,
    output wire [31:0]   prog_data,
    input  wire [31:0]   frames_rendered,
    output wire          running,
    output wire          restart,
    // status (also reported by STATUS)
    output wire [31:0]   active_words,
    output wire [31:0]   malformed,
    output wire [31:0]   loads
);
    // ---- receive paths ----
    wire       e_valid, e_first, e_last, e_err;
    wire [7:0] e_data;
    wire [47:0] peer_mac;
    rmii_rx #(.DEVICE_MAC(DEVICE_MAC), .ETHERTYPE(ETHERTYPE)) u_rmii_rx (
        .clk(clk), .rst(rst), .crs_dv(rmii_crs_dv), .rxd(rmii_rxd),
        .out_valid(e_valid), .out_data(e_data), .out_first(e_first), .out_last(e_last),
        .out_err(e_err), .src_mac(peer_mac));

    wire       u_valid, u_err;
    wire [7:0] u_data;
    uart_rx #(.CLKS_PER_BIT(CLKS_PER_BIT)) u_uart_rx (
        .clk(clk), .rst(rst), .rx(uart_rx), .valid(u_valid), .data(u_data), .err(u_err));

    wire       s_valid, s_first, s_last, s_err;
    wire [7:0] s_data;
    cobs_decoder u_cobs_dec (
        .clk(clk), .rst(rst), .in_valid(u_valid), .in_data(u_data), .in_err(u_err),
        .out_valid(s_valid), .out_data(s_data), .out_first(s_first), .out_last(s_last),
        .out_err(s_err));

    // ---- arbitration: a frame owns the engine from its first byte to its end ----
    reg owner;        // 0: Ethernet, 1: serial
    reg locked;
    reg reply_serial; // the link of the frame being answered
    wire accepting;   // the engine takes a new frame now
    wire take_e = !locked || owner == 1'b0;
    wire take_s = !locked || owner == 1'b1;
    wire pick_s = locked ? owner : (s_valid && s_first && !(e_valid && e_first));
    always @(posedge clk) begin
        if (rst) begin
            locked <= 1'b0;
            owner <= 1'b0;
        end else if (!locked) begin
            if (e_valid && e_first) begin locked <= 1'b1; owner <= 1'b0; end
            else if (s_valid && s_first) begin locked <= 1'b1; owner <= 1'b1; end
        end else if ((owner == 1'b0 && e_last) || (owner == 1'b1 && s_last)) begin
            locked <= 1'b0;
        end
        if (in_valid && in_first && accepting) reply_serial <= pick_s;  // the frame answered next
    end
    wire       in_valid = pick_s ? (s_valid && take_s) : (e_valid && take_e);
    wire [7:0] in_data  = pick_s ? s_data : e_data;
    wire       in_first = pick_s ? s_first : e_first;
    wire       in_last  = locked ? (owner ? s_last : e_last) : (s_last || e_last);
    wire       in_err   = locked ? (owner ? s_err : e_err) : (s_last ? s_err : e_err);

    // ---- engine and memory ----
    wire          mem_we;
    wire [AW:0]   mem_addr;
    wire [31:0]   mem_wdata, mem_rdata;
    wire          bank;
    wire          reply_start, reply_busy;
    wire [5:0]    reply_len, reply_idx;
    wire [7:0]    reply_byte;
    /* verilator lint_off UNUSEDSIGNAL */  // reported by STATUS only
    wire [31:0]   active_crc;
    wire [15:0]   active_load;
    /* verilator lint_on UNUSEDSIGNAL */
    rend3r_engine #(.AW(AW)) u_engine (
        .clk(clk), .rst(rst), .in_valid(in_valid), .in_data(in_data), .in_first(in_first),
        .in_last(in_last), .in_err(in_err),
        .mem_we(mem_we), .mem_addr(mem_addr), .mem_wdata(mem_wdata), .mem_rdata(mem_rdata),
        .bank(bank), .reply_start(reply_start), .reply_len(reply_len), .reply_idx(reply_idx),
        .reply_byte(reply_byte), .reply_busy(reply_busy), .frames_rendered(frames_rendered),
        .running(running), .restart(restart), .accepting(accepting), .active_words(active_words),
        .active_crc(active_crc), .active_load(active_load), .malformed(malformed), .loads(loads));

    program_memory #(.AW(AW), .INIT_FILE(INIT_FILE)) u_mem (
        .clk(clk), .a_we(mem_we), .a_addr(mem_addr), .a_wdata(mem_wdata), .a_rdata(mem_rdata),
        .b_clk(prog_clk), .b_bank(bank), .b_addr(prog_addr), .b_rdata(prog_data));

    // ---- reply transmitters ----
    wire [5:0] c_idx, r_idx;
    wire       c_busy, r_busy;
    wire       t_valid, t_ready;
    wire [7:0] t_data;
    assign reply_idx = c_busy ? c_idx : r_idx;
    assign reply_busy = c_busy || r_busy;
    cobs_tx u_cobs_tx (
        .clk(clk), .rst(rst), .start(reply_start && reply_serial), .len(reply_len),
        .idx(c_idx), .buf_byte(reply_byte), .busy(c_busy),
        .out_valid(t_valid), .out_data(t_data), .out_ready(t_ready));
    uart_tx #(.CLKS_PER_BIT(CLKS_PER_BIT)) u_uart_tx (
        .clk(clk), .rst(rst), .valid(t_valid), .data(t_data), .ready(t_ready), .tx(uart_tx));
    rmii_tx #(.SOURCE_MAC(SOURCE_MAC), .ETHERTYPE(ETHERTYPE)) u_rmii_tx (
        .clk(clk), .rst(rst), .start(reply_start && !reply_serial), .len(reply_len),
        .dst_mac(peer_mac), .idx(r_idx), .buf_byte(reply_byte), .busy(r_busy),
        .tx_en(rmii_tx_en), .txd(rmii_txd));
endmodule
