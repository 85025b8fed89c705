/* UART0 at 1 000 000 baud: 16 MHz / (8 (UBRR + 1)) with U2X, UBRR = 1, exact. */
#include "uart.h"

#include <avr/io.h>

void uart_init(void) {
    UCSR0A = _BV(U2X0);
    UBRR0 = 1;
    UCSR0B = _BV(RXEN0) | _BV(TXEN0);
    UCSR0C = _BV(UCSZ01) | _BV(UCSZ00);
}

void uart_write(const uint8_t *data, uint8_t length) {
    for (uint8_t i = 0; i < length; i++) {
        while (!(UCSR0A & _BV(UDRE0))) {
        }
        UDR0 = data[i];
    }
}

uint8_t uart_read(uint8_t *out) {
    if (!(UCSR0A & _BV(RXC0))) return 0;
    *out = UDR0;
    return 1;
}
