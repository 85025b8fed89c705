/* UART0 (the Mega 2560's USB bridge) at 1 000 000 baud, 8N1, both ways through queues that
 * interrupts serve: the receive interrupt only moves a byte into its queue (the USART holds
 * just 2 bytes, 20 µs at this rate), and sending a frame costs the main loop a copy, not the
 * line's time. */
#ifndef ARTICULA_UART_H
#define ARTICULA_UART_H

#include <stdint.h>

void uart_init(void);
/* Queue bytes to send (waits only while the queue is full). */
void uart_write(const uint8_t *data, uint8_t length);
/* Bytes the send queue has room for now (uart_write of that many does not wait); it holds
 * 511. */
uint16_t uart_space(void);
/* The received bytes waiting, up to `most`, into out: how many (never waits). */
uint8_t uart_take(uint8_t *out, uint8_t most);
/* 1 when a received byte waits in the queue. */
uint8_t uart_pending(void);
/* Received bytes lost since start-up: those of the USART's data overruns (DOR: its buffer
 * and shift register were full when a further byte began), estimated from the time the
 * receive interrupt was held off (uart.c), and the bytes the receive queue had no room for,
 * exactly; saturates at 65535 (called at least once per 256 losses, as STATUS does, it misses
 * none). */
uint16_t uart_overruns(void);
/* The main loop came round: the receive path is served (the start of an overrun's
 * estimate). */
void uart_alive(void);

#endif
