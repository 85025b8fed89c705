/* UART0 (the Mega 2560's USB bridge) at 1 000 000 baud, 8N1, both ways through queues that
 * interrupts serve: no received byte is lost while the main loop works, and sending a frame
 * costs the main loop a copy, not the line's time. */
#ifndef ARTICULA_UART_H
#define ARTICULA_UART_H

#include <stdint.h>

void uart_init(void);
/* Queue bytes to send (waits only while the queue is full). */
void uart_write(const uint8_t *data, uint8_t length);
/* 1 and the next received byte in *out, else 0 (never waits). */
uint8_t uart_read(uint8_t *out);
/* 1 when a received byte waits in the queue. */
uint8_t uart_pending(void);

#endif
