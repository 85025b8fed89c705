/* The rigs' serial protocol (docs/protocol.md), device side: COBS frames, CRC-16/CCITT-FALSE,
 * the device's sequence numbers. Byte for byte what articula/rigs/protocol.py speaks. */
#ifndef ARTICULA_PROTOCOL_H
#define ARTICULA_PROTOCOL_H

#include <stdint.h>

#define PROTOCOL_VERSION 2
#define MAX_FRAME 254 /* bytes of type, seq, body and CRC: one COBS block */

enum kind {
    HELLO = 0x01, SET_GAINS = 0x02, SET_REFERENCE = 0x03, START = 0x04, STOP = 0x05,
    SET_OUTPUT = 0x06, SET_DAMPING = 0x07, STREAM = 0x08, STATUS = 0x09, GET = 0x0A,
    INFO = 0x81, ACK = 0x82, ERROR = 0x83, TELEMETRY = 0x84, DONE = 0x85
};
enum error_code { BAD_FRAME = 1, UNKNOWN = 2, BAD_VALUE = 3, BUSY = 4, STOPPED = 5 };

/* A command as received: its type, the host's sequence number, its body. */
struct command {
    uint8_t kind;
    uint16_t seq;
    const uint8_t *body;
    uint8_t length;
};

uint16_t crc16(const uint8_t *data, uint8_t length);
/* Send one frame (type, the device's next seq, body) through uart_write. */
void frame_send(uint8_t kind, const uint8_t *body, uint8_t length);
/* Feed one received byte; returns 1 and fills *out when it completes a valid frame (a frame
 * that fails COBS or its CRC is dropped: the host sends it again). A byte within a frame
 * costs the main loop some 30 cycles (COBS a byte at a time), so that it keeps up with the
 * line beside the receive interrupt's 80; the delimiter checks the CRC, some 25 cycles a
 * byte of the frame. */
uint8_t frame_receive(uint8_t byte, struct command *out);
/* ERROR naming a command: its seq, a code and a text (up to MAX_FRAME - 8 characters, what a
 * frame holds; tests/firmware checks every text of firmware/src fits). */
void send_error(uint16_t seq, uint8_t code, const char *text);
/* A reply's body as it is built (INFO, ERROR, a GET's ACK): one buffer for all of them. */
extern uint8_t reply_body[MAX_FRAME - 5];
/* ACK naming a command. */
void send_ack(uint16_t seq);
/* The little-endian u32 `value` into out[0..3]. */
void put_u32(uint8_t *out, uint32_t value);

#endif
