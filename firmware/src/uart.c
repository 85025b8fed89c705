/* UART0 at 1 000 000 baud: 16 MHz / (8 (UBRR + 1)) with U2X, UBRR = 1, exact. */
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
static volatile uint8_t overruns_dor, overruns_full; /* wrapping counts, cheap to bump */
static uint16_t overruns;                            /* their sum since start-up, saturating */
static uint8_t seen_dor, seen_full;

/* A byte came: into the queue, and the losses counted (the status first: DOR belongs to the
 * byte in UDR0 and is gone once it is read). About 40 cycles: every other interrupt and
 * every section with interrupts off is kept well under the 160 cycles of a byte. */
ISR(USART0_RX_vect) {
    uint8_t status = UCSR0A;
    uint8_t byte = UDR0, head = rx_head;
    if (status & _BV(DOR0)) overruns_dor++;
    if ((uint8_t)(head + 1) != rx_tail) rx[head] = byte, rx_head = (uint8_t)(head + 1);
    else overruns_full++; /* full: the host resends the frame it was part of */
}

void uart_init(void) {
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
