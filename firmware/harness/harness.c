/* Runs a rig's firmware ELF on a simulated ATmega2560 at 16 MHz (simavr), UART0 behind a
 * pseudo-terminal, and couples its pins to a simulated plant in lock step.
 *
 *   harness FIRMWARE.elf [--plant] [--tick-us N] [--realtime]
 *
 * Prints "uart0 at <device path>" once the firmware's start-up (its INFO, sent unasked) has
 * gone to the pty, then runs until killed (or, with --plant, until its standard input closes:
 * the plant process has ended). The host opens that path as it would open /dev/ttyACM0.
 * SIGUSR1 resets the board, as its reset button does: the firmware starts again.
 *
 * --plant: a plant process (articula's rigs/firmware.py) on the other end of standard input
 * and output. Each ADC conversion the firmware starts is one control period: the harness
 * writes
 *     sample <adc channel> <PORTA> <PORTC> <PORTH> <OCR1A> <OCR3A> <OCR4A> <step cycles>
 * (the output registers as the firmware left them, and the CPU cycles of the previous control
 * step) and waits for "<adc code> <encoder count> [<hex bytes>]": the code the conversion
 * reads, the count the quadrature encoder on D2/D3 (PE4/PE5) reaches, one edge every
 * EDGE_CYCLES, and bytes a sensor sends on Serial1 (RX1, at 115 200 baud). With --tick-us
 * the plant has its own step instead: an exchange every N µs of a run (adc channel 255),
 * from N µs after its start. A run starting (the firmware's probe, probe.h) is
 * "run <seed>"; its end "end".
 *
 * Time: during a run the simulation runs as fast as the plant answers (--realtime: at the
 * wall clock's pace); at rest it keeps the wall clock's pace, so an idle rig costs little. */
#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <pty.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <termios.h>
#include <time.h>
#include <unistd.h>

#include "avr_adc.h"
#include "avr_ioport.h"
#include "avr_uart.h"
#include "sim_avr.h"
#include "sim_elf.h"
#include "sim_interrupts.h"
#include "sim_time.h"

#define GPIOR0 0x3E /* data-space addresses of the ATmega2560's registers */
#define GPIOR1 0x4A
#define PORTA 0x22
#define PORTC 0x28
#define PORTH 0x102
#define OCR1AL 0x88
#define OCR3AL 0x98
#define OCR4AL 0xA8
#define UCSR0B 0xC1
#define RXEN0 0x10
#define PROBE_RUN 1 /* probe.h's marks */
#define PROBE_STEP 2
#define PROBE_END 4
#define POLL_CYCLES 1600     /* the pty is served every 100 µs of simulated time */
#define EDGE_CYCLES 64       /* between the encoder's edges */
#define BYTE_CYCLES 160      /* a byte's time on the line at 1 Mbaud */
#define SENSOR_BYTE_CYCLES 1389 /* at 115 200 baud */
#define NO_CONVERSION 255
#define QUEUE 65536          /* bytes each way between the pty and the UART */
#define OUT_HIGH_WATER 4096  /* the simulation waits for the host above this */
#define VCC_MV 5000
#define START_CYCLES 320000  /* 20 ms: the firmware's start-up, before the path is printed */

struct queue {
    uint8_t data[QUEUE];
    uint32_t head, tail;
};

static avr_t *avr;
static int master = -1;
static struct queue to_avr, to_host, to_sensor_rx;
static int xon = 1;
static int plant, realtime, running;
static uint32_t seed;
static uint8_t seed_bytes;
static avr_irq_t *uart_in, *sensor_in, *adc_in, *encoder_pin[2];
static avr_cycle_count_t tick_cycles; /* the plant's own step (--tick-us); 0: per conversion */
static int32_t encoder_count, encoder_target;
static uint8_t encoder_phase; /* the pins' state in the Gray sequence 00, 10, 11, 01 */
static avr_cycle_count_t step_cycles, entered[64];
static uint8_t step_vector[64];
static volatile sig_atomic_t reset_pressed; /* SIGUSR1: reset the board */

static uint32_t queue_size(const struct queue *q) { return q->head - q->tail; }

static void fail(const char *what) {
    fprintf(stderr, "harness: %s: %s\n", what, strerror(errno));
    exit(1);
}

/* A byte the firmware sent: queued for the host. */
static void uart_output(avr_irq_t *irq, uint32_t value, void *param) {
    (void)irq, (void)param;
    to_host.data[to_host.head++ % QUEUE] = (uint8_t)value;
}

static void uart_xon(avr_irq_t *irq, uint32_t value, void *param) {
    (void)irq, (void)value, (void)param;
    xon = 1;
}

/* The host's next byte onto the line, one every byte time (10 bits at 1 Mbaud), as the USB
 * bridge delivers them; held while the UART is off or its receive buffer is full. */
static avr_cycle_count_t uart_feed(avr_t *a, avr_cycle_count_t when, void *param) {
    (void)a, (void)param;
    if (!queue_size(&to_avr)) return 0;
    if (xon && (avr->data[UCSR0B] & RXEN0)) avr_raise_irq(uart_in, to_avr.data[to_avr.tail++ % QUEUE]);
    return when + BYTE_CYCLES;
}

static void uart_xoff(avr_irq_t *irq, uint32_t value, void *param) {
    (void)irq, (void)param;
    xon = !value;
}

/* With --plant: end when the plant process has (its end of standard input closed), as
 * reading the plant's answer does during a run. */
static void exit_without_plant(void) {
    struct pollfd input = {STDIN_FILENO, 0, 0};
    if (plant && poll(&input, 1, 0) > 0 && (input.revents & (POLLHUP | POLLERR | POLLNVAL)))
        exit(0);
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
    if (queue_size(&to_avr) && !avr_cycle_timer_status(avr, uart_feed, NULL))
        avr_cycle_timer_register(avr, BYTE_CYCLES, uart_feed, NULL);
    return when + (running ? POLL_CYCLES : 10 * POLL_CYCLES);
}

/* One encoder edge toward the target, then the next one EDGE_CYCLES later. */
static avr_cycle_count_t encoder_edge(avr_t *a, avr_cycle_count_t when, void *param) {
    (void)a, (void)param;
    if (encoder_count == encoder_target) return 0;
    int step = encoder_target > encoder_count ? 1 : -1;
    encoder_count += step;
    encoder_phase = (uint8_t)((encoder_phase + step) & 3);
    static const uint8_t pins[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    avr_raise_irq(encoder_pin[0], pins[encoder_phase][0]);
    avr_raise_irq(encoder_pin[1], pins[encoder_phase][1]);
    return encoder_count == encoder_target ? 0 : when + EDGE_CYCLES;
}

static uint16_t reg16(uint16_t low) { return (uint16_t)(avr->data[low] | (avr->data[low + 1] << 8)); }

/* The sensor's next byte onto Serial1. */
static avr_cycle_count_t sensor_feed(avr_t *a, avr_cycle_count_t when, void *param) {
    (void)a, (void)param;
    if (!queue_size(&to_sensor_rx)) return 0;
    avr_raise_irq(sensor_in, to_sensor_rx.data[to_sensor_rx.tail++ % QUEUE]);
    return when + SENSOR_BYTE_CYCLES;
}

/* One control period of the plant: the outputs the firmware left, then what it answers. */
static void exchange(unsigned channel) {
    printf("sample %u %u %u %u %u %u %u %llu\n", channel, avr->data[PORTA], avr->data[PORTC],
           avr->data[PORTH], reg16(OCR1AL), reg16(OCR3AL), reg16(OCR4AL),
           (unsigned long long)step_cycles);
    fflush(stdout);
    step_cycles = 0;
    static char line[4096];
    unsigned code;
    long count;
    int used = 0;
    if (!fgets(line, sizeof line, stdin)) exit(0); /* the plant is gone */
    if (sscanf(line, "%u %ld %n", &code, &count, &used) < 2) {
        fprintf(stderr, "harness: the plant answered %s", line);
        exit(1);
    }
    if (channel < 8) {
        /* simavr's ADC reads floor(mV · 1023 / VCC): the smallest mV that reads `code`. */
        uint32_t mv = (uint32_t)((code * VCC_MV + 1022) / 1023);
        avr_raise_irq(adc_in + channel, mv);
    }
    encoder_target = (int32_t)count;
    avr_cycle_timer_cancel(avr, encoder_edge, NULL);
    if (encoder_target != encoder_count) avr_cycle_timer_register(avr, 1, encoder_edge, NULL);
    unsigned byte;
    for (char *at = line + used; sscanf(at, "%2x", &byte) == 1; at += 2)
        to_sensor_rx.data[to_sensor_rx.head++ % QUEUE] = (uint8_t)byte;
    if (queue_size(&to_sensor_rx) && !avr_cycle_timer_status(avr, sensor_feed, NULL))
        avr_cycle_timer_register(avr, 1, sensor_feed, NULL);
}

/* A conversion starts: with a plant that steps per conversion, one control period. */
static void adc_trigger(avr_irq_t *irq, uint32_t value, void *param) {
    (void)irq, (void)param;
    if (!running || tick_cycles) return; /* at rest the last reading stands */
    union {
        avr_adc_mux_t mux;
        uint32_t value;
    } e = {.value = value};
    exchange(e.mux.src);
}

/* The plant's own step (--tick-us), through a run. */
static avr_cycle_count_t plant_tick(avr_t *a, avr_cycle_count_t when, void *param) {
    (void)a, (void)param;
    if (!running) return 0;
    exchange(NO_CONVERSION);
    return when + tick_cycles;
}

/* An interrupt that marked itself part of the control step starts or ends (reti). */
static void vector_running(avr_irq_t *irq, uint32_t value, void *param) {
    (void)irq;
    uint8_t vector = (uint8_t)(uintptr_t)param;
    if (value) entered[vector] = avr->cycle;
    else step_cycles += avr->cycle - entered[vector];
}

static void probe(avr_t *a, avr_io_addr_t addr, uint8_t v, void *param) {
    (void)param;
    a->data[addr] = v;
    if (addr == GPIOR1) { /* the seed, least significant byte first */
        uint8_t k = seed_bytes++ % 4;
        seed = k == 0 ? v : seed | (uint32_t)v << (8 * k);
        return;
    }
    if (v == PROBE_RUN) {
        running = 1;
        seed_bytes = 0;
        encoder_count = encoder_target = 0; /* the firmware counts from 0 at a run's start */
        if (plant) printf("run %u\n", seed), fflush(stdout);
        to_sensor_rx.tail = to_sensor_rx.head; /* the sensor's line starts afresh */
        if (plant && tick_cycles) {
            avr_cycle_timer_cancel(a, plant_tick, NULL);
            avr_cycle_timer_register(a, tick_cycles, plant_tick, NULL);
        }
    } else if (v == PROBE_END) {
        running = 0;
        if (plant) printf("end\n"), fflush(stdout);
    } else if (v == PROBE_STEP && a->interrupts.running_ptr) {
        /* From now on every activation of this interrupt counts whole (entry to reti). */
        avr_int_vector_t *vector = a->interrupts.running[a->interrupts.running_ptr - 1];
        if (!step_vector[vector->vector]) {
            step_vector[vector->vector] = 1;
            entered[vector->vector] = a->cycle;
            avr_irq_register_notify(vector->irq + AVR_INT_IRQ_RUNNING, vector_running,
                                    (void *)(uintptr_t)vector->vector);
        }
    }
}

static void press_reset(int signal) {
    (void)signal;
    reset_pressed = 1;
}

/* The board's reset: the firmware starts again from its reset vector with its I/O registers
 * cleared (simavr's avr_reset); a run going on ends there. simavr drops every cycle timer,
 * the harness's own too, so the pty's is registered again. */
static void reset_board(void) {
    reset_pressed = 0;
    avr_reset(avr);
    if (running && plant) printf("end\n"), fflush(stdout);
    running = 0;
    xon = 1;
    encoder_target = encoder_count;
    to_sensor_rx.tail = to_sensor_rx.head;
    avr_cycle_timer_register(avr, POLL_CYCLES, serve_pty, NULL);
}

static uint64_t wall_ns(void) {
    struct timespec now;
    clock_gettime(CLOCK_MONOTONIC, &now);
    return (uint64_t)now.tv_sec * 1000000000u + (uint64_t)now.tv_nsec;
}

/* Sleeping firmware: keep the wall clock's pace at rest (or always with --realtime), counted
 * from when pacing began (simavr's own pacing counts from the start, and after a fast run it
 * would stop the clock until the wall caught up). */
static void sleep_callback(avr_t *a, avr_cycle_count_t how_long) {
    static int paced;
    static uint64_t anchor_ns;
    static avr_cycle_count_t anchor_cycle;
    if (!realtime && running) {
        paced = 0;
        return;
    }
    uint64_t now = wall_ns();
    uint64_t due = anchor_ns + (a->cycle + how_long - anchor_cycle) * 1000u / (a->frequency / 1000000u);
    if (!paced || now > due + 50000000u) { /* starting, or 50 ms behind: count from now */
        paced = 1;
        anchor_ns = now;
        anchor_cycle = a->cycle;
        return;
    }
    if (due > now + 200000u) usleep((useconds_t)((due - now) / 1000u)); /* sleeps of 0.2 ms+ */
}

int main(int argc, char **argv) {
    static elf_firmware_t firmware; /* zeroed */
    for (int i = 2; i < argc; i++) {
        if (!strcmp(argv[i], "--plant")) plant = 1;
        else if (!strcmp(argv[i], "--realtime")) realtime = 1;
        else if (!strcmp(argv[i], "--tick-us") && i + 1 < argc)
            tick_cycles = 16u * (avr_cycle_count_t)strtoul(argv[++i], NULL, 10);
        else argc = 0;
    }
    if (argc < 2 || elf_read_firmware(argv[1], &firmware) != 0) {
        fprintf(stderr, "usage: harness FIRMWARE.elf [--plant] [--tick-us N] [--realtime]\n");
        return 2;
    }
    avr = avr_make_mcu_by_name("atmega2560");
    if (avr == NULL) return 2;
    avr_init(avr);
    avr->frequency = 16000000;
    avr->vcc = avr->avcc = avr->aref = VCC_MV;
    avr_load_firmware(avr, &firmware);
    avr->sleep = sleep_callback;

    uint32_t flags = 0; /* no stdio echo, no sleeping while the firmware polls the UART */
    avr_ioctl(avr, AVR_IOCTL_UART_GET_FLAGS('0'), &flags);
    flags &= ~(uint32_t)(AVR_UART_FLAG_STDIO | AVR_UART_FLAG_POLL_SLEEP);
    avr_ioctl(avr, AVR_IOCTL_UART_SET_FLAGS('0'), &flags);
    uart_in = avr_io_getirq(avr, AVR_IOCTL_UART_GETIRQ('0'), UART_IRQ_INPUT);
    avr_irq_register_notify(avr_io_getirq(avr, AVR_IOCTL_UART_GETIRQ('0'), UART_IRQ_OUTPUT),
                            uart_output, NULL);
    avr_irq_register_notify(avr_io_getirq(avr, AVR_IOCTL_UART_GETIRQ('0'), UART_IRQ_OUT_XON),
                            uart_xon, NULL);
    avr_irq_register_notify(avr_io_getirq(avr, AVR_IOCTL_UART_GETIRQ('0'), UART_IRQ_OUT_XOFF),
                            uart_xoff, NULL);
    avr_register_io_write(avr, GPIOR0, probe, NULL);
    avr_register_io_write(avr, GPIOR1, probe, NULL);
    adc_in = avr_io_getirq(avr, AVR_IOCTL_ADC_GETIRQ, ADC_IRQ_ADC0);
    if (plant) {
        avr_irq_register_notify(avr_io_getirq(avr, AVR_IOCTL_ADC_GETIRQ, ADC_IRQ_OUT_TRIGGER),
                                adc_trigger, NULL);
        for (int k = 0; k < 2; k++)
            encoder_pin[k] = avr_io_getirq(avr, AVR_IOCTL_IOPORT_GETIRQ('E'), 4 + k);
        sensor_in = avr_io_getirq(avr, AVR_IOCTL_UART_GETIRQ('1'), UART_IRQ_INPUT);
    }

    int slave;
    char path[256];
    if (openpty(&master, &slave, path, NULL, NULL) < 0) fail("openpty");
    struct termios tio;
    tcgetattr(slave, &tio);
    cfmakeraw(&tio);
    tcsetattr(slave, TCSANOW, &tio);
    fcntl(master, F_SETFL, fcntl(master, F_GETFL) | O_NONBLOCK);
    /* The slave stays open here, so the line does not hang up between a host's sessions. */
    avr_cycle_timer_register(avr, POLL_CYCLES, serve_pty, NULL);
    struct sigaction reset = {.sa_handler = press_reset, .sa_flags = SA_RESTART};
    sigemptyset(&reset.sa_mask);
    sigaction(SIGUSR1, &reset, NULL);
    /* The firmware's start-up first: its INFO is whole in the pty when a host opens it (a
     * host that opens it mid-frame would count the frame's tail as damaged). */
    int announced = 0;
    for (;;) {
        int state = avr_run(avr);
        if (state == cpu_Done || state == cpu_Crashed) return state == cpu_Done ? 0 : 1;
        if (reset_pressed) reset_board();
        if (!announced && avr->cycle >= START_CYCLES && !queue_size(&to_host)) {
            announced = 1;
            printf("uart0 at %s\n", path);
            fflush(stdout);
        }
    }
}
