/* Runs a rig's firmware ELF on a simulated ATmega2560 at 16 MHz (simavr), UART0 behind a
 * pseudo-terminal, and couples its pins to a simulated plant in lock step.
 *
 *   harness FIRMWARE.elf [--plant] [--tick-us N] [--realtime] [--trace FILE]
 *
 * Prints "uart0 at <device path>" once the firmware's start-up (its INFO, sent unasked) has
 * gone to the pty, then runs until killed (or, with --plant, until its standard input closes:
 * the plant process has ended). The host opens that path as it would open /dev/ttyACM0;
 * line.c receives its bytes as the chip's USART does (a two-byte buffer, data overruns).
 * SIGUSR1 resets the board, as its reset button does (MCUSR: EXTRF); SIGUSR2 hangs the
 * firmware's main loop (a bug's endless loop, interrupts still on): the program's own
 * `rjmp .` of avr-libc's exit, jumped to from the main loop. The watchdog is simavr's; a
 * watchdog reset sets WDRF, power-on PORF.
 *
 * --plant: a plant process (articula's rigs/firmware.py) on the other end of standard input
 * and output. Each ADC conversion the firmware starts is one control period: the harness
 * writes
 *     sample <adc channel> <PORTA> <PORTC> <PORTH> <OCR1A> <OCR3A> <OCR4A> <cycles> <latency>
 * (the output registers as the firmware left them; the CPU cycles of the previous control
 * step: the time its marked interrupts ran, the interrupts nested in them not counted; and
 * its latency: the longest from a marked interrupt's entry to its reti, nested ones
 * included) and waits
 * for "<adc code> <encoder count> [<hex bytes>]": the code the conversion reads, the count
 * the quadrature encoder on D2/D3 (PE4/PE5) reaches, its edges spread over EDGE_SPAN_CYCLES
 * (EDGE_CYCLES apart at the closest), and bytes a
 * sensor sends on Serial1 (RX1, at 115 200 baud). With --tick-us the plant has its own step
 * instead: an exchange every N µs of a run (adc channel 255), from N µs after its start. A
 * run starting (the firmware's probe, probe.h) is "run <seed>"; its end "end".
 *
 * --trace FILE: a line "pins <cycle> <PORTA> <PORTB> <PORTC> <PORTE> <PORTH> <TCCR1A>
 * <TCCR3A> <TCCR4A> <OCR1A> <OCR3A> <OCR4A>" whenever one of those registers changes (after
 * the instruction that changed it), the host's and the firmware's frames (line.c), "run",
 * "end", "reset", "hang": what a logic analyser on the board would see. And, what it would
 * not: "irqoff <cycle> <cycles> <address>" each time a section with interrupts off (SREG's
 * I bit clear: a cli, an interrupt's entry, up to the sei, reti or SREG restore that sets it
 * again) is the longest yet, at its end: its length in CPU cycles as simavr counts them
 * (the chip's 5-cycle interrupt response not included) and the hex byte address it began
 * at (after its cli, or the interrupt's vector). The start-up, before the first sei, is not
 * such a section.
 *
 * Time: during a run the simulation runs as fast as the plant answers, while the host talks
 * (a byte within the last HOST_QUIET_CYCLES); otherwise, and always with --realtime, it keeps
 * the wall clock's pace, so a host's silence lasts as long for the firmware as for the host
 * and an idle rig costs little. */
#include <errno.h>
#include <poll.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "avr_adc.h"
#include "avr_ioport.h"
#include "avr_uart.h"
#include "harness.h"
#include "sim_elf.h"
#include "sim_interrupts.h"
#include "sim_time.h"

#define GPIOR0 0x3E /* data-space addresses of the ATmega2560's registers */
#define GPIOR1 0x4A
#define MCUSR 0x54
#define PORF 0x01
#define EXTRF 0x02
#define PROBE_RUN 1 /* probe.h's marks */
#define PROBE_BUSY 2
#define PROBE_IDLE 3
#define PROBE_END 4
#define EDGE_CYCLES 64          /* between the encoder's edges, at the closest */
#define EDGE_SPAN_CYCLES 1280   /* a period's edges spread over this, within the conversion's
                                 * 1664 cycles (13 ADC clocks at /128), as a turning shaft spaces
                                 * them: bunched 64 cycles apart, an edge came before the last
                                 * one's interrupt read the pins once an interrupt was late */
#define SENSOR_BYTE_CYCLES 1389 /* at 115 200 baud */
#define NO_CONVERSION 255
#define SENSOR_QUEUE 65536
#define VCC_MV 5000
#define START_CYCLES 320000 /* 20 ms: the firmware's start-up, before the path is printed */
#define HOST_QUIET_CYCLES (100 * CYCLES_PER_MS) /* a run goes fast while the host talks */

/* The registers a trace follows (data-space addresses), in its "pins" line's order. */
static const uint16_t traced[] = {0x22, 0x25, 0x28, 0x2E, 0x102, 0x80, 0x90, 0xA0, 0x88, 0x98, 0xA8};
#define TRACED (sizeof traced / sizeof traced[0])
#define OCR1AL_AT 8 /* OCR1A is 16 bits: its high byte follows */

avr_t *avr;
int running;
FILE *trace;
static int plant, realtime;
static uint32_t seed;
static uint8_t seed_bytes;
static avr_irq_t *sensor_in, *adc_in, *encoder_pin[2];
static avr_cycle_count_t tick_cycles; /* the plant's own step (--tick-us); 0: per conversion */
static int32_t encoder_count, encoder_target;
static avr_cycle_count_t edge_cycles = EDGE_CYCLES; /* between this period's edges */
static uint8_t encoder_phase; /* the pins' state in the Gray sequence 00, 10, 11, 01 */
static struct {
    uint8_t data[SENSOR_QUEUE];
    uint32_t head, tail;
} to_sensor;
/* The control step's cycles: the time its marked interrupts ran themselves (not the ones
 * nested in them), and its latency: the longest from a marked interrupt's entry to its reti,
 * the nested ones included. The interrupt running now (0: the main loop), since when. */
static avr_cycle_count_t step_cycles, step_latency, entered[64], top_since;
static uint8_t top;
static uint8_t step_vector[64];
static volatile sig_atomic_t reset_pressed, hang_pressed; /* SIGUSR1, SIGUSR2 */
static avr_flashaddr_t hang_at;                            /* the firmware's `rjmp .` */
static int hung;
static void (*core_reset)(avr_t *);
/* Interrupts off (SREG's I): on at the last look; once on since the (re)start; the section
 * going on, from when and where; the longest so far. */
static int interrupts_on, interrupts_were_on;
static avr_cycle_count_t off_since, off_longest;
static avr_flashaddr_t off_at;

void trace_event(const char *what, const char *text) {
    if (!trace) return;
    fprintf(trace, "%s %llu %s\n", what, (unsigned long long)avr->cycle, text);
    fflush(trace);
}

void exit_without_plant(void) {
    struct pollfd input = {STDIN_FILENO, 0, 0};
    if (plant && poll(&input, 1, 0) > 0 && (input.revents & (POLLHUP | POLLERR | POLLNVAL)))
        exit(0);
}

/* A "pins" line when a traced register changed since the last look. */
static void trace_pins(void) {
    static uint8_t last[TRACED + 1];
    static int started;
    uint8_t now[TRACED + 1];
    for (size_t k = 0; k < TRACED; k++) now[k] = avr->data[traced[k]];
    now[TRACED] = avr->data[traced[OCR1AL_AT] + 1];
    if (started && !memcmp(now, last, sizeof now)) return;
    started = 1;
    memcpy(last, now, sizeof now);
    char text[128];
    int n = 0;
    for (size_t k = 0; k < TRACED; k++)
        n += snprintf(text + n, sizeof text - n, k ? " %u" : "%u",
                      k == OCR1AL_AT ? now[k] | now[TRACED] << 8 : now[k]);
    trace_event("pins", text);
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
    return encoder_count == encoder_target ? 0 : when + edge_cycles;
}

/* After each instruction: a section with interrupts off begins or ends (the longest
 * traced). A byte at 1 Mbaud takes 160 cycles: a section longer than that can overrun the
 * USART. */
static void watch_interrupts(void) {
    int on = avr->sreg[S_I];
    if (on == interrupts_on) return;
    interrupts_on = on;
    if (!on) {
        off_since = avr->cycle;
        off_at = avr->pc;
    } else if (interrupts_were_on && avr->cycle - off_since > off_longest) {
        off_longest = avr->cycle - off_since;
        char text[48];
        snprintf(text, sizeof text, "%llu %x", (unsigned long long)off_longest, (unsigned)off_at);
        trace_event("irqoff", text);
    }
    interrupts_were_on |= on;
}

static uint16_t reg16(uint16_t low) { return (uint16_t)(avr->data[low] | (avr->data[low + 1] << 8)); }

/* The sensor's next byte onto Serial1. */
static avr_cycle_count_t sensor_feed(avr_t *a, avr_cycle_count_t when, void *param) {
    (void)a, (void)param;
    if (to_sensor.head == to_sensor.tail) return 0;
    avr_raise_irq(sensor_in, to_sensor.data[to_sensor.tail++ % SENSOR_QUEUE]);
    return when + SENSOR_BYTE_CYCLES;
}

/* One control period of the plant: the outputs the firmware left, then what it answers. */
static void exchange(unsigned channel) {
    printf("sample %u %u %u %u %u %u %u %llu %llu\n", channel, avr->data[0x22], avr->data[0x28],
           avr->data[0x102], reg16(0x88), reg16(0x98), reg16(0xA8),
           (unsigned long long)step_cycles, (unsigned long long)step_latency);
    fflush(stdout);
    step_cycles = step_latency = 0;
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
    long edges = labs((long)encoder_target - (long)encoder_count);
    edge_cycles = edges > 1 && EDGE_SPAN_CYCLES / edges > EDGE_CYCLES ? EDGE_SPAN_CYCLES / edges
                                                                       : EDGE_CYCLES;
    avr_cycle_timer_cancel(avr, encoder_edge, NULL);
    if (encoder_target != encoder_count) avr_cycle_timer_register(avr, 1, encoder_edge, NULL);
    unsigned byte;
    for (char *at = line + used; sscanf(at, "%2x", &byte) == 1; at += 2)
        to_sensor.data[to_sensor.head++ % SENSOR_QUEUE] = (uint8_t)byte;
    if (to_sensor.head != to_sensor.tail && !avr_cycle_timer_status(avr, sensor_feed, NULL))
        avr_cycle_timer_register(avr, 1, sensor_feed, NULL);
}

/* A conversion starts: with a plant that steps per conversion, one control period. */
static void adc_trigger(avr_irq_t *irq, uint32_t value, void *param) {
    (void)irq, (void)param;
    if (!running || tick_cycles || !plant) return; /* at rest the last reading stands */
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
    else if (avr->cycle - entered[vector] > step_latency) step_latency = avr->cycle - entered[vector];
}

/* The interrupt that runs changes (value: its vector; 0: back in the main loop): the time
 * the last one ran goes to the step if it is one of the step's. */
static void any_running(avr_irq_t *irq, uint32_t value, void *param) {
    (void)irq, (void)param;
    if (step_vector[top]) step_cycles += avr->cycle - top_since;
    top = (uint8_t)(value & 63);
    top_since = avr->cycle;
}

/* The firmware's probe marks (probe.h). In an interrupt a busy mark enrols that interrupt
 * as part of the control step (timed from then on). */
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
        trace_event("run", "");
        if (plant) printf("run %u\n", seed), fflush(stdout);
        to_sensor.tail = to_sensor.head; /* the sensor's line starts afresh */
        if (plant && tick_cycles) {
            avr_cycle_timer_cancel(a, plant_tick, NULL);
            avr_cycle_timer_register(a, tick_cycles, plant_tick, NULL);
        }
    } else if (v == PROBE_END) {
        running = 0;
        trace_event("end", "");
        if (plant) printf("end\n"), fflush(stdout);
    } else if (v == PROBE_BUSY && a->interrupts.running_ptr) {
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

static void press_hang(int signal) {
    (void)signal;
    hang_pressed = 1;
}

/* Every reset of the board (the button, the watchdog): the firmware starts again from its
 * reset vector with its I/O registers cleared (simavr's avr_reset); a run going on ends
 * there. simavr drops every cycle timer, the harness's own too: the pty's is registered
 * again. */
static void board_reset(avr_t *a) {
    if (core_reset) core_reset(a);
    if (running && plant) printf("end\n"), fflush(stdout);
    running = 0;
    hung = 0;
    interrupts_on = interrupts_were_on = 0; /* the start-up again, interrupts off */
    encoder_target = encoder_count;
    to_sensor.tail = to_sensor.head;
    line_reset();
    line_serve();
    trace_event("reset", "");
}

/* SIGUSR2: once the main loop runs with interrupts on, send it to the firmware's endless
 * loop (avr-libc's exit: cli, then rjmp to itself; the jump skips the cli). */
static void hang_main_loop(void) {
    if (avr->interrupts.running_ptr || !avr->sreg[S_I] || avr->state != cpu_Running) return;
    hang_pressed = 0;
    hung = 1;
    avr->pc = hang_at;
    trace_event("hang", "");
}

/* The firmware's `rjmp .` after avr-libc's `cli` in exit (F8 94 FF CF); 0 if none. */
static avr_flashaddr_t endless_loop(void) {
    for (avr_flashaddr_t at = 0; at + 4 <= avr->flashend; at += 2)
        if (avr->flash[at] == 0xF8 && avr->flash[at + 1] == 0x94 && avr->flash[at + 2] == 0xFF &&
            avr->flash[at + 3] == 0xCF)
            return at + 2;
    return 0;
}

static uint64_t wall_ns(void) {
    struct timespec now;
    clock_gettime(CLOCK_MONOTONIC, &now);
    return (uint64_t)now.tv_sec * 1000000000u + (uint64_t)now.tv_nsec;
}

/* Sleeping firmware: keep the wall clock's pace at rest, while the host is quiet in a run
 * (or always with --realtime), counted from when pacing began (simavr's own pacing counts
 * from the start, and after a fast run it would stop the clock until the wall caught up). */
static void sleep_callback(avr_t *a, avr_cycle_count_t how_long) {
    static int paced;
    static uint64_t anchor_ns;
    static avr_cycle_count_t anchor_cycle;
    if (!realtime && running && a->cycle - line_heard() < HOST_QUIET_CYCLES) {
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
    const char *trace_path = NULL;
    for (int i = 2; i < argc; i++) {
        if (!strcmp(argv[i], "--plant")) plant = 1;
        else if (!strcmp(argv[i], "--realtime")) realtime = 1;
        else if (!strcmp(argv[i], "--tick-us") && i + 1 < argc)
            tick_cycles = 16u * (avr_cycle_count_t)strtoul(argv[++i], NULL, 10);
        else if (!strcmp(argv[i], "--trace") && i + 1 < argc) trace_path = argv[++i];
        else argc = 0;
    }
    if (argc < 2 || elf_read_firmware(argv[1], &firmware) != 0) {
        fprintf(stderr, "usage: harness FIRMWARE.elf [--plant] [--tick-us N] [--realtime] "
                        "[--trace FILE]\n");
        return 2;
    }
    if (trace_path && !(trace = fopen(trace_path, "w"))) {
        fprintf(stderr, "harness: %s: %s\n", trace_path, strerror(errno));
        return 2;
    }
    avr = avr_make_mcu_by_name("atmega2560");
    if (avr == NULL) return 2;
    avr_init(avr);
    avr->frequency = 16000000;
    avr->vcc = avr->avcc = avr->aref = VCC_MV;
    avr_load_firmware(avr, &firmware);
    avr->sleep = sleep_callback;
    avr->data[MCUSR] = PORF; /* powered on */
    core_reset = avr->reset;
    avr->reset = board_reset;
    hang_at = endless_loop();

    uint32_t flags = 0; /* no stdio echo, no sleeping while the firmware polls the UART */
    avr_ioctl(avr, AVR_IOCTL_UART_GET_FLAGS('0'), &flags);
    flags &= ~(uint32_t)(AVR_UART_FLAG_STDIO | AVR_UART_FLAG_POLL_SLEEP);
    avr_ioctl(avr, AVR_IOCTL_UART_SET_FLAGS('0'), &flags);
    avr_register_io_write(avr, GPIOR0, probe, NULL);
    avr_register_io_write(avr, GPIOR1, probe, NULL);
    avr_irq_register_notify(avr->interrupts.irq + AVR_INT_IRQ_RUNNING, any_running, NULL);
    adc_in = avr_io_getirq(avr, AVR_IOCTL_ADC_GETIRQ, ADC_IRQ_ADC0);
    avr_irq_register_notify(avr_io_getirq(avr, AVR_IOCTL_ADC_GETIRQ, ADC_IRQ_OUT_TRIGGER),
                            adc_trigger, NULL);
    if (plant) {
        for (int k = 0; k < 2; k++)
            encoder_pin[k] = avr_io_getirq(avr, AVR_IOCTL_IOPORT_GETIRQ('E'), 4 + k);
        sensor_in = avr_io_getirq(avr, AVR_IOCTL_UART_GETIRQ('1'), UART_IRQ_INPUT);
    }
    char path[256];
    line_open(path, sizeof path);
    struct sigaction reset = {.sa_handler = press_reset, .sa_flags = SA_RESTART};
    sigemptyset(&reset.sa_mask);
    sigaction(SIGUSR1, &reset, NULL);
    struct sigaction hang = {.sa_handler = press_hang, .sa_flags = SA_RESTART};
    sigemptyset(&hang.sa_mask);
    sigaction(SIGUSR2, &hang, NULL);
    /* The firmware's start-up first: its INFO is whole in the pty when a host opens it (a
     * host that opens it mid-frame would count the frame's tail as damaged). */
    int announced = 0;
    for (;;) {
        int state = avr_run(avr);
        if (state == cpu_Done || state == cpu_Crashed) return state == cpu_Done ? 0 : 1;
        if (trace) trace_pins(), watch_interrupts();
        if (reset_pressed) {
            reset_pressed = 0;
            avr_reset(avr);
            avr->data[MCUSR] = EXTRF; /* the reset button's flag, as the chip sets it */
        }
        if (hang_pressed && hang_at) hang_main_loop();
        if (!announced && avr->cycle >= START_CYCLES && !line_to_host()) {
            announced = 1;
            printf("uart0 at %s\n", path);
            fflush(stdout);
        }
    }
}
