/* The rigs' serial protocol, device side (protocol.h). */
#include "protocol.h"

#include <string.h>

#include "uart.h"

static uint16_t device_seq;

/* One byte into CRC-16/CCITT-FALSE (polynomial 0x1021, no reflection): the byte-wise form
 * of the polynomial's shifts (x^12 + x^5 + 1), about 25 cycles where avr-libc's bit loop
 * (_crc_xmodem_update) takes about 70. */
static uint16_t crc_update(uint16_t crc, uint8_t byte) {
    uint8_t x = (uint8_t)((crc >> 8) ^ byte);
    x ^= (uint8_t)(x >> 4);
    return (uint16_t)((crc << 8) ^ ((uint16_t)x << 12) ^ ((uint16_t)x << 5) ^ x);
}

uint16_t crc16(const uint8_t *data, uint8_t length) {
    uint16_t crc = 0xFFFF;
    for (uint8_t i = 0; i < length; i++) crc = crc_update(crc, data[i]);
    return crc;
}

void frame_send(uint8_t kind, const uint8_t *body, uint8_t length) {
    static uint8_t raw[MAX_FRAME];
    static uint8_t out[MAX_FRAME + 2];
    raw[0] = kind;
    raw[1] = (uint8_t)(device_seq & 0xFF);
    raw[2] = (uint8_t)(device_seq >> 8);
    device_seq++;
    memcpy(raw + 3, body, length);
    uint8_t n = (uint8_t)(3 + length);
    uint16_t crc = crc16(raw, n);
    raw[n++] = (uint8_t)(crc & 0xFF);
    raw[n++] = (uint8_t)(crc >> 8);
    /* COBS: each zero becomes the distance to the next one (the frame fits one block). */
    uint8_t code_at = 0, code = 1, m = 1;
    for (uint8_t i = 0; i < n; i++) {
        if (raw[i] == 0) {
            out[code_at] = code;
            code_at = m++;
            code = 1;
        } else {
            out[m++] = raw[i];
            code++;
        }
    }
    out[code_at] = code;
    out[m++] = 0; /* the delimiter */
    uart_write(out, m);
}

/* The frame being received, decoded as its bytes come: the payload so far, the bytes left
 * in the current COBS block (0: the next byte is a block's code), that code. Its CRC is
 * checked at the delimiter, not byte by byte: at full line rate the receive interrupt leaves
 * the main loop some 70 cycles a byte, and a frame that turns out overlong costs nothing. */
static uint8_t payload[MAX_FRAME];
static uint8_t received, left, code, bad;

/* One decoded byte of the payload; too many mark the frame bad (dropped at its delimiter). */
static inline void put(uint8_t byte) {
    if (received >= sizeof payload) bad = 1;
    else payload[received++] = byte;
}

/* The delimiter: whole blocks, at least type, seq and CRC, and the CRC matches. Apart from
 * frame_receive (noinline), so that a byte within a frame does not pay for the registers
 * this part needs. */
static __attribute__((noinline)) uint8_t frame_end(struct command *out) {
    uint8_t n = received, ok = !bad && code && left == 0 && n >= 5;
    uint16_t sent = ok ? (uint16_t)(payload[n - 2] | ((uint16_t)payload[n - 1] << 8)) : 0;
    ok = ok && sent == crc16(payload, (uint8_t)(n - 2));
    received = left = code = bad = 0;
    if (!ok) return 0;
    out->kind = payload[0];
    out->seq = (uint16_t)(payload[1] | ((uint16_t)payload[2] << 8));
    out->body = payload + 3;
    out->length = (uint8_t)(n - 5);
    return 1;
}

uint8_t frame_receive(uint8_t byte, struct command *out) {
    if (byte == 0) return frame_end(out);
    if (bad) return 0;
    if (left == 0) { /* a block's code: the zero the previous block stood for, first */
        if (code && code < 0xFF) put(0);
        code = byte;
        left = (uint8_t)(byte - 1);
    } else {
        put(byte);
        left--;
    }
    return 0;
}

void put_u32(uint8_t *out, uint32_t value) {
    for (uint8_t k = 0; k < 4; k++) out[k] = (uint8_t)(value >> (8 * k));
}

void send_ack(uint16_t seq) {
    uint8_t body[2] = {(uint8_t)(seq & 0xFF), (uint8_t)(seq >> 8)};
    frame_send(ACK, body, 2);
}

uint8_t reply_body[MAX_FRAME - 5];

void send_error(uint16_t seq, uint8_t code, const char *text) {
    uint8_t *body = reply_body; /* a frame's whole body: texts go out whole */
    uint8_t n = 0;
    body[n++] = (uint8_t)(seq & 0xFF);
    body[n++] = (uint8_t)(seq >> 8);
    body[n++] = code;
    while (*text && n < sizeof reply_body) body[n++] = (uint8_t)*text++;
    frame_send(ERROR, body, n);
}
