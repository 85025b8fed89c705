/* UART0 at 1 000 000 baud: 16 MHz / (8 (UBRR + 1)) with U2X, UBRR = 1, exact. Timer5,
 * free-running at 16 MHz / 64 (4 µs a tick), is its receive path's clock. */
#include "uart.h"

#include <avr/interrupt.h>
#include <avr/io.h>
#include <util/atomic.h>

/* The receive queue holds 256 bytes, so its uint8_t indices wrap by themselves; the send
 * queue TX bytes, room for a reply beside the telemetry (rig.c keeps it free). */
#define TX 512
static volatile uint8_t rx[256], tx[TX];
static volatile uint8_t rx_head, rx_tail; /* the interrupt's end, the main loop's */
static volatile uint16_t tx_tail;         /* the interrupt's end */
static uint16_t tx_head;                  /* the main loop's */
static volatile uint8_t overruns_dor, overruns_full; /* wrapping byte counts, cheap to bump */
static uint16_t overruns;                            /* their sum since start-up, saturating */
static uint8_t seen_dor, seen_full;
/* When the receive path was last known to be served (TCNT5L, 4 µs ticks, wrapping): the last
 * byte read, or the main loop's pass (uart_alive). */
static volatile uint8_t served_at;
#define KEPT 2 /* bytes an overrun leaves in the USART's 2-byte buffer */

/* Bytes lost in a data overrun that ends now, `held` ticks [4 µs] after the receive path was
 * last served: those the line carried meanwhile at 10 µs a byte, less the KEPT (the byte in
 * the shift register, kept too, is matched by the one on the line, counted in `held`). The
 * chip says only "one or more" (DOR0); this is within a byte of the harness's exact count
 * when the bytes came back to back since the last one read (a burst behind a command), more
 * when the line was idle before them, and at least 1. Inlined: a call from the receive
 * interrupt would make it save every register a call may clobber. */
static inline __attribute__((always_inline)) uint8_t overrun_bytes(uint8_t held) {
    uint8_t carried = (uint8_t)(((uint16_t)held * 103) >> 8); /* held · 4 / 10, no division */
    return carried > KEPT ? (uint8_t)(carried - KEPT) : 1;
}

/* A byte came: into the queue, and the losses counted in bytes (the status first: DOR
 * belongs to the byte in UDR0 and is gone once it is read). About 80 cycles, 110 at most
 * (tools/interrupts_off.py): every section with interrupts off is kept under the 160 cycles
 * of a byte. */
ISR(USART0_RX_vect) {
    uint8_t status = UCSR0A, now = TCNT5L;
    uint8_t byte = UDR0, head = rx_head;
    if (status & _BV(DOR0)) overruns_dor += overrun_bytes((uint8_t)(now - served_at));
    served_at = now;
    if ((uint8_t)(head + 1) != rx_tail) rx[head] = byte, rx_head = (uint8_t)(head + 1);
    else overruns_full++; /* full: the host resends the frame it was part of */
}

void uart_alive(void) { served_at = TCNT5L; }

void uart_init(void) {
    TCCR5B = _BV(CS51) | _BV(CS50); /* Timer5 free-running at 16 MHz / 64 */
    UCSR0A = _BV(U2X0);
    UBRR0 = 1;
    UCSR0B = _BV(RXEN0) | _BV(TXEN0) | _BV(RXCIE0);
    UCSR0C = _BV(UCSZ01) | _BV(UCSZ00);
}

/* The transmitter is free: the next queued byte; quiet after the last one. The interrupt is
 * only enabled with a byte queued: simavr, unlike the chip, clears the UDRE flag on entering
 * it, and an entry with nothing to send would leave the next enable without an interrupt. */
ISR(USART0_UDRE_vect) {
    uint16_t at = tx_tail;
    UDR0 = tx[at];
    tx_tail = at = (uint16_t)((at + 1) % TX);
    if (at == tx_head) UCSR0B &= (uint8_t)~_BV(UDRIE0);
}

void uart_write(const uint8_t *data, uint8_t length) {
    while (length) {
        uint16_t room = uart_space(), head = tx_head;
        uint8_t n = room < length ? (uint8_t)room : length; /* 0: full, wait for the line */
        for (uint8_t i = 0; i < n; i++, head = (uint16_t)((head + 1) % TX)) tx[head] = *data++;
        length = (uint8_t)(length - n);
        if (n) ATOMIC_BLOCK(ATOMIC_RESTORESTATE) { /* published whole, then the interrupt on */
                tx_head = head;
                UCSR0B |= _BV(UDRIE0);
            }
    }
}

uint16_t uart_space(void) {
    uint16_t tail;
    ATOMIC_BLOCK(ATOMIC_RESTORESTATE) { tail = tx_tail; }
    return (uint16_t)((tail + TX - tx_head - 1) % TX);
}

uint8_t uart_pending(void) { return rx_head != rx_tail; }

uint8_t uart_take(uint8_t *out, uint8_t most) {
    uint8_t n = 0, tail = rx_tail, head = rx_head;
    while (tail != head && n < most) out[n++] = rx[tail++];
    rx_tail = tail;
    return n;
}

uint16_t uart_overruns(void) {
    uint8_t dor = overruns_dor, full = overruns_full; /* single bytes: read whole */
    uint16_t more = (uint8_t)(dor - seen_dor) + (uint8_t)(full - seen_full);
    seen_dor = dor, seen_full = full;
    overruns = overruns > 0xFFFF - more ? 0xFFFF : (uint16_t)(overruns + more);
    return overruns;
}
