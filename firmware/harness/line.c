/* The host's line: bytes between the pty and UART0, received as the ATmega2560's USART
 * receives them.
 *
 * simavr's UART keeps a 64-byte receive FIFO, which hides what a late receive interrupt
 * costs on the chip. Here the host's bytes go onto the line one every byte time (10 bits at
 * 1 Mbaud, 160 cycles) and enter the USART as the datasheet has it: a two-byte receive
 * buffer (UDR0) and the shift register behind it. A byte that ends while the buffer is full
 * waits in the shift register; when the next byte's start bit comes and it still waits, it
 * is lost and DOR0 set in UCSR0A (a data overrun), and the trace says "overrun". The harness
 * fills simavr's FIFO itself (never more than two bytes) and raises RXC0; the firmware's
 * read of UDR0 goes through simavr (its own pacing of reads turned off), then the byte in
 * the shift register moves up, and RXC0's interrupt comes again while a byte is left. Bytes that reach a disabled receiver are lost, as on the chip.
 *
 * The host's bytes reach the line in batches at the USB bridge's 1 ms frames, at a phase
 * drawn for each batch (the USB clock is not the board's), so a host's command meets the
 * firmware at any point of its control period.
 *
 * The trace (--trace) has a line per host frame as its delimiter ends on the line ("rx"),
 * per firmware frame as its delimiter goes into UDR0 ("tx"), and per lost byte. */
#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <pty.h>
#include <stdlib.h>
#include <string.h>
#include <termios.h>
#include <unistd.h>

#include "avr_uart.h"
#include "harness.h"
#include "sim_io.h"

DEFINE_FIFO(uint16_t, uart_fifo);

#define UCSR0A 0xC0 /* data-space addresses of the ATmega2560's registers */
#define UCSR0B 0xC1
#define UDR0 0xC6
#define RXEN0 0x10
#define DOR0 0x08
#define BYTE_CYCLES 160     /* a byte's time on the line at 1 Mbaud (8N1: 10 bits) */
#define POLL_CYCLES 1600    /* the pty is served every 100 µs of simulated time */
#define USB_FRAME_CYCLES 16000 /* the USB bridge's 1 ms frames */
#define QUEUE 65536         /* bytes each way between the pty and the UART */
#define OUT_HIGH_WATER 4096 /* the simulation waits for the host above this */
#define FRAME_TRACE 1024    /* bytes of a frame the trace shows */

struct queue {
    uint8_t data[QUEUE];
    uint32_t head, tail;
};

static int master = -1;
static struct queue to_avr, to_host;
static avr_uart_t *uart0;
static avr_io_read_t simavr_read;
static void *simavr_read_param;
/* The line and the USART: the byte on the line (its start bit came), the one waiting in the
 * shift register behind a full buffer, the cycle the host's last byte began. */
static int on_line, in_shift;
static uint8_t line_byte, shift_byte;
static avr_cycle_count_t heard;
static uint32_t jitter = 12345; /* the USB frame's phase, drawn (a fixed seed) */
struct frame_text {
    char hex[2 * FRAME_TRACE + 1];
    int length;
};
static struct frame_text rx_text, tx_text;

static uint32_t queue_size(const struct queue *q) { return q->head - q->tail; }

/* A frame's bytes for the trace, written out at its delimiter. */
static void frame_byte(struct frame_text *f, const char *what, uint8_t byte) {
    if (byte == 0) {
        f->hex[2 * f->length] = 0;
        trace_event(what, f->hex);
        f->length = 0;
    } else if (f->length < FRAME_TRACE) {
        snprintf(f->hex + 2 * f->length, 3, "%02x", byte);
        f->length++;
    }
}

/* A byte the firmware sent: queued for the host. */
static void uart_output(avr_irq_t *irq, uint32_t value, void *param) {
    (void)irq, (void)param;
    to_host.data[to_host.head++ % QUEUE] = (uint8_t)value;
    if (trace) frame_byte(&tx_text, "tx", (uint8_t)value);
}

static uint32_t buffered(void) { return uart_fifo_get_read_size(&uart0->input); }

/* Into the USART's receive buffer (UDR0), RXC0 raised. */
static void to_buffer(uint8_t byte) {
    uart_fifo_write(&uart0->input, byte);
    avr_raise_interrupt(avr, &uart0->rxc);
}

/* A byte's stop bit: into the buffer, else into the shift register to wait. */
static void byte_ends(uint8_t byte) {
    if (!(avr->data[UCSR0B] & RXEN0)) return; /* a receiver that is off loses it */
    if (buffered() < 2) to_buffer(byte);
    else in_shift = 1, shift_byte = byte;
}

/* The line, one byte time a step: the byte on it ends; the host's next begins. A start bit
 * while a byte still waits in the shift register overruns it. */
static avr_cycle_count_t uart_line(avr_t *a, avr_cycle_count_t when, void *param) {
    (void)a, (void)param;
    if (on_line) {
        on_line = 0;
        byte_ends(line_byte);
    }
    if (!queue_size(&to_avr)) return 0;
    line_byte = to_avr.data[to_avr.tail++ % QUEUE];
    on_line = 1;
    heard = when;
    if (trace) frame_byte(&rx_text, "rx", line_byte);
    if (in_shift) {
        in_shift = 0;
        avr->data[UCSR0A] |= DOR0;
        trace_event("overrun", "");
    }
    return when + BYTE_CYCLES;
}

/* The firmware reads UDR0: through simavr's UART (its check on reads faster than its own
 * byte time turned off: the line above keeps the time), then the waiting byte moves up. */
static uint8_t udr_read(avr_t *a, avr_io_addr_t addr, void *param) {
    (void)param;
    uart0->rx_cnt = 0;
    uint8_t value = simavr_read(a, addr, simavr_read_param);
    if (in_shift && buffered() < 2) {
        in_shift = 0;
        uart_fifo_write(&uart0->input, shift_byte);
    }
    /* RXC0 is a level on the chip: set while the buffer holds a byte, so its interrupt comes
     * again for the next one (simavr's UART re-raises it with its own timer, off here). */
    if (buffered()) avr_raise_interrupt(avr, &uart0->rxc);
    return value;
}

/* Move bytes between the pty and the UART; wait for the host when it lags far behind. */
static avr_cycle_count_t serve_pty(avr_t *a, avr_cycle_count_t when, void *param) {
    (void)a, (void)param;
    if (!running) exit_without_plant(); /* in a run, the plant's next answer tells */
    for (;;) {
        if (QUEUE - queue_size(&to_avr) >= 4096) {
            uint8_t buffer[4096];
            ssize_t got = read(master, buffer, sizeof buffer);
            for (ssize_t i = 0; i < got; i++) to_avr.data[to_avr.head++ % QUEUE] = buffer[i];
        }
        while (queue_size(&to_host)) {
            uint32_t at = to_host.tail % QUEUE;
            uint32_t length = queue_size(&to_host);
            if (length > QUEUE - at) length = QUEUE - at;
            ssize_t put = write(master, to_host.data + at, length);
            if (put <= 0) break;
            to_host.tail += (uint32_t)put;
        }
        if (queue_size(&to_host) <= OUT_HIGH_WATER) break;
        struct pollfd waiting = {master, POLLOUT, 0};
        poll(&waiting, 1, 100);
        exit_without_plant();
    }
    /* New bytes from the host wait for the USB bridge's next 1 ms frame, whose clock is not
     * the board's: they reach the line at any phase of the firmware's control period. */
    if (queue_size(&to_avr) && !avr_cycle_timer_status(avr, uart_line, NULL)) {
        jitter = jitter * 1103515245u + 12345u;
        avr_cycle_timer_register(avr, BYTE_CYCLES + (jitter >> 8) % USB_FRAME_CYCLES, uart_line, NULL);
    }
    return when + (running ? POLL_CYCLES : 10 * POLL_CYCLES);
}

void line_open(char *path, size_t size) {
    for (avr_io_t *io = avr->io_port; io; io = io->next)
        if (!strcmp(io->kind, "uart") && ((avr_uart_t *)io)->name == '0') uart0 = (avr_uart_t *)io;
    if (!uart0) {
        fprintf(stderr, "harness: this simavr has no UART0\n");
        exit(1);
    }
    avr_io_addr_t io = AVR_DATA_TO_IO(UDR0);
    simavr_read = avr->io[io].r.c, simavr_read_param = avr->io[io].r.param;
    avr->io[io].r.c = udr_read, avr->io[io].r.param = NULL;
    avr_irq_register_notify(avr_io_getirq(avr, AVR_IOCTL_UART_GETIRQ('0'), UART_IRQ_OUTPUT),
                            uart_output, NULL);
    int slave;
    char name[256];
    if (openpty(&master, &slave, name, NULL, NULL) < 0) {
        fprintf(stderr, "harness: openpty: %s\n", strerror(errno));
        exit(1);
    }
    struct termios tio;
    tcgetattr(slave, &tio);
    cfmakeraw(&tio);
    tcsetattr(slave, TCSANOW, &tio);
    fcntl(master, F_SETFL, fcntl(master, F_GETFL) | O_NONBLOCK);
    /* The slave stays open here, so the line does not hang up between a host's sessions. */
    snprintf(path, size, "%s", name);
    line_serve();
}

void line_reset(void) {
    on_line = in_shift = 0;
    rx_text.length = 0;
}

void line_serve(void) { avr_cycle_timer_register(avr, POLL_CYCLES, serve_pty, NULL); }

uint32_t line_to_host(void) { return queue_size(&to_host); }

avr_cycle_count_t line_heard(void) { return heard; }
