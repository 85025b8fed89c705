/* The PneuNet rig's firmware (chapter 2), first step: the handshake of docs/protocol.md.
 * INFO is byte for byte what articula's emulated PneuNet sends (rigs/pneunet.py); every other
 * command is refused with ERROR "unknown" until the 30 Hz PID loop lands (issue 16). */
#include <stdint.h>
#include <string.h>

#include "protocol.h"
#include "uart.h"

#define RIG_PNEUNET 1
#define SAMPLE_PERIOD_US 33333UL /* the book's 30 Hz valve PWM */

static const char *const channels[][2] = {{"reference", "deg"}, {"angle", "deg"},
                                          {"pwm", "counts"}};

static void send_info(void) {
    static uint8_t body[96];
    uint8_t n = 0;
    body[n++] = PROTOCOL_VERSION;
    body[n++] = RIG_PNEUNET;
    body[n++] = 0; /* firmware 0.1.0 */
    body[n++] = 1;
    body[n++] = 0;
    for (uint8_t k = 0; k < 4; k++) body[n++] = (uint8_t)(SAMPLE_PERIOD_US >> (8 * k));
    body[n++] = 3;
    for (uint8_t c = 0; c < 3; c++) {
        for (uint8_t t = 0; t < 2; t++) {
            uint8_t length = (uint8_t)strlen(channels[c][t]);
            body[n++] = length;
            memcpy(body + n, channels[c][t], length);
            n = (uint8_t)(n + length);
        }
    }
    frame_send(INFO, body, n);
}

int main(void) {
    uart_init();
    struct command command;
    uint8_t byte;
    for (;;) {
        if (!uart_read(&byte) || !frame_receive(byte, &command)) continue;
        if (command.kind == HELLO) send_info();
        else send_error(command.seq, UNKNOWN, "not in this firmware yet");
    }
}
