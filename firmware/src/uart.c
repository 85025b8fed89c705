/* UART0 at 1 000 000 baud: 16 MHz / (8 (UBRR + 1)) with U2X, UBRR = 1, exact. */
#include "uart.h"

#include <avr/interrupt.h>
#include <avr/io.h>
#include <util/atomic.h>

/* Both queues hold 256 bytes, a whole frame, so their uint8_t indices wrap by themselves. */
static volatile uint8_t rx[256], tx[256];
static volatile uint8_t rx_head, tx_tail; /* the interrupts' ends */
static uint8_t rx_tail, tx_head;           /* the main loop's ends */
static volatile uint16_t overruns;

/* A byte came: into the queue, and the losses counted (the status first: DOR belongs to the
 * byte in UDR0 and is gone once it is read). About 40 cycles: every other interrupt and
 * every section with interrupts off is kept well under the 160 cycles of a byte. */
ISR(USART0_RX_vect) {
    uint8_t status = UCSR0A;
    uint8_t byte = UDR0;
    uint8_t lost = (status & _BV(DOR0)) ? 1 : 0;
    if ((uint8_t)(rx_head + 1) != rx_tail) rx[rx_head++] = byte;
    else lost++; /* full: the host resends the frame it was part of */
    if (lost && overruns < 0xFFFF) overruns++;
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
    UDR0 = tx[tx_tail++];
    if (tx_tail == tx_head) UCSR0B &= (uint8_t)~_BV(UDRIE0);
}

void uart_write(const uint8_t *data, uint8_t length) {
    for (uint8_t i = 0; i < length; i++) {
        while ((uint8_t)(tx_head + 1) == tx_tail) { /* full: wait for the line */
        }
        tx[tx_head++] = data[i];
        ATOMIC_BLOCK(ATOMIC_RESTORESTATE) { UCSR0B |= _BV(UDRIE0); }
    }
}

uint8_t uart_space(void) { return (uint8_t)(tx_tail - tx_head - 1); }

uint8_t uart_pending(void) { return rx_head != rx_tail; }

uint8_t uart_read(uint8_t *out) {
    if (rx_head == rx_tail) return 0;
    *out = rx[rx_tail++];
    return 1;
}

uint16_t uart_overruns(void) {
    uint16_t count;
    ATOMIC_BLOCK(ATOMIC_RESTORESTATE) { count = overruns; }
    return count;
}
