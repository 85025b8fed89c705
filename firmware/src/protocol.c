/* The rigs' serial protocol, device side (protocol.h). */
#include "protocol.h"

#include <string.h>
#include <util/crc16.h>

#include "uart.h"

static uint16_t device_seq;
static uint8_t rx[MAX_FRAME + 1]; /* a COBS block: its code byte and the payload */
static uint8_t rx_length;
static uint8_t rx_overflow; /* more bytes than a frame holds before the delimiter */
static uint8_t payload[MAX_FRAME];

uint16_t crc16(const uint8_t *data, uint8_t length) {
    /* CRC-16/CCITT-FALSE is XMODEM's CRC (polynomial 0x1021, no reflection) started at
     * 0xFFFF; avr-libc's update step is hand-written assembly. */
    uint16_t crc = 0xFFFF;
    for (uint8_t i = 0; i < length; i++) crc = _crc_xmodem_update(crc, data[i]);
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

/* The payload of a COBS block in rx, or 0 when it is malformed or longer than a frame. */
static uint8_t cobs_decode(void) {
    uint8_t i = 0, n = 0;
    while (i < rx_length) {
        uint8_t code = rx[i];
        if (code == 0 || i + code > rx_length || n + code > sizeof payload) return 0;
        for (uint8_t k = 1; k < code; k++) payload[n++] = rx[i + k];
        i = (uint8_t)(i + code);
        if (code < 0xFF && i < rx_length) payload[n++] = 0;
    }
    return n;
}

uint8_t frame_receive(uint8_t byte, struct command *out) {
    if (byte != 0) {
        if (rx_length < sizeof rx) rx[rx_length++] = byte;
        else rx_overflow = 1; /* too long: dropped at the delimiter */
        return 0;
    }
    uint8_t n = rx_overflow ? 0 : cobs_decode();
    rx_length = 0;
    rx_overflow = 0;
    if (n < 5) return 0;
    uint16_t crc = (uint16_t)(payload[n - 2] | ((uint16_t)payload[n - 1] << 8));
    if (crc16(payload, (uint8_t)(n - 2)) != crc) return 0;
    out->kind = payload[0];
    out->seq = (uint16_t)(payload[1] | ((uint16_t)payload[2] << 8));
    out->body = payload + 3;
    out->length = (uint8_t)(n - 5);
    return 1;
}

void send_ack(uint16_t seq) {
    uint8_t body[2] = {(uint8_t)(seq & 0xFF), (uint8_t)(seq >> 8)};
    frame_send(ACK, body, 2);
}

void send_error(uint16_t seq, uint8_t code, const char *text) {
    static uint8_t body[MAX_FRAME - 5]; /* a frame's whole body: texts go out whole */
    uint8_t n = 0;
    body[n++] = (uint8_t)(seq & 0xFF);
    body[n++] = (uint8_t)(seq >> 8);
    body[n++] = code;
    while (*text && n < sizeof body) body[n++] = (uint8_t)*text++;
    frame_send(ERROR, body, n);
}
