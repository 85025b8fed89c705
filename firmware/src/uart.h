/* UART0 (the Mega 2560's USB bridge) at 1 000 000 baud, 8N1, polled. */
#ifndef ARTICULA_UART_H
#define ARTICULA_UART_H

#include <stdint.h>

void uart_init(void);
void uart_write(const uint8_t *data, uint8_t length);
/* 1 and the byte in *out when one was received, else 0 (never waits). */
uint8_t uart_read(uint8_t *out);

#endif
