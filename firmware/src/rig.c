/* The command loop, the run's life and its one safe state (rig.h). */
#include "rig.h"

#include <avr/interrupt.h>
#include <avr/sleep.h>
#include <avr/wdt.h>
#include <string.h>
#include <util/atomic.h>

#include "probe.h"
#include "protocol.h"
#include "uart.h"

#define RING 8                 /* samples between the control step and the telemetry */
#define HOST_TIMEOUT_MS 500    /* START's default host_timeout_ms */
#define MIN_HOST_TIMEOUT_MS 20 /* START's range for it */
#define MAX_HOST_TIMEOUT_MS 60000
#define REPLY_ROOM (MAX_FRAME + 2) /* the send queue's room for any reply: a frame, stuffed */
#define RECEIVE_BATCH 32           /* bytes a main-loop pass takes at most (~1.5k cycles) */
enum reset_cause { POWER_ON = 0, EXTERNAL = 1, WATCHDOG = 2, BROWN_OUT = 3 };
enum run_end { NOT_ENDED = 0, ENDED_DONE = 1, ENDED_STOP = 2, ENDED_HOST = 3, ENDED_ERROR = 4 };

/* MCUSR as the chip left it, read before the C runtime starts (.init3) and cleared, with the
 * watchdog off: after a watchdog reset the chip keeps it running at 16 ms, which the start-up
 * must not outlast. .noinit: the runtime does not zero it afterwards. */
static uint8_t reset_flags __attribute__((section(".noinit")));
void read_reset_cause(void) __attribute__((naked, used, section(".init3")));
void read_reset_cause(void) {
    reset_flags = MCUSR;
    MCUSR = 0;
    wdt_disable();
}

volatile uint8_t rig_event;
static const struct rig *rig;
static volatile uint16_t clock_ms;
static volatile uint8_t stalled; /* the watchdog's interrupt came: the main loop was late */

/* The sample ring from the control step to the telemetry, both in the main loop. */
struct sample {
    uint32_t index;
    float values[MAX_CHANNELS];
};
static struct sample ring[RING];
static volatile uint8_t ring_head, ring_tail; /* head: the control step's; tail: the main loop's */
static volatile uint32_t samples;            /* of the run going on, or of the last one */

/* The run: its control on (running); over, its last samples and DONE to send (draining);
 * why the last one ended; its START's seq; the last START carried out (a START sent again
 * is only acknowledged); the decimation; the host's last valid frame and its timeout. */
static uint8_t running, draining, ended;
static volatile uint8_t finished; /* the control step's word that the run is over */
static uint16_t run_seq, last_start;
static uint8_t have_last_start;
static uint16_t decimation = 1;
static uint16_t heard_ms, host_timeout_ms = HOST_TIMEOUT_MS;

ISR(TIMER0_COMPA_vect) { clock_ms++; }

/* The watchdog's first timeout (interrupt and reset mode): the main loop has not come round
 * for 32 ms, hung or late. Outputs off now; the chip resets at the next timeout unless the
 * main loop comes back, sees `stalled`, ends the run and arms the interrupt again. Interrupts
 * on from its first instruction (safe() makes its own short atomic writes), so that its
 * prologue does not hold the host's bytes up. A main loop hung with interrupts off gets no
 * such interrupt: only the reset at the second timeout. */
ISR(WDT_vect, ISR_NOBLOCK) {
    if (rig) rig->safe();
    stalled = 1;
}

uint16_t rig_clock_ms(void) {
    uint16_t now;
    ATOMIC_BLOCK(ATOMIC_RESTORESTATE) { now = clock_ms; }
    return now;
}

/* The watchdog at 32 ms, its interrupt first, a reset at the second timeout. */
static void watchdog_on(void) {
    ATOMIC_BLOCK(ATOMIC_RESTORESTATE) {
        wdt_reset();
        WDTCSR = _BV(WDCE) | _BV(WDE); /* the change sequence: the next write within 4 cycles */
        WDTCSR = _BV(WDIE) | _BV(WDE) | _BV(WDP0);
    }
}

void adc_start(uint8_t channel) {
    ADMUX = _BV(REFS0) | channel;
    ADCSRA = _BV(ADEN) | _BV(ADPS2) | _BV(ADPS1) | _BV(ADPS0); /* 16 MHz / 128 */
    ADCSRA |= _BV(ADSC);
}

float *rig_slot(void) {
    static float scratch[MAX_CHANNELS];
    return (uint8_t)((ring_head + 1) % RING) != ring_tail ? ring[ring_head].values : scratch;
}

void rig_sample(void) {
    uint8_t next = (uint8_t)((ring_head + 1) % RING);
    if (next != ring_tail) { /* full: the sample is not sent (the host sees the gap) */
        ring[ring_head].index = samples;
        ring_head = next;
    }
    samples++;
}

void rig_done(void) { finished = 1; }

float read_float(const uint8_t *body, uint8_t offset) {
    float value;
    memcpy(&value, body + offset, sizeof value);
    return value;
}

void write_float(uint8_t *body, uint8_t offset, float value) {
    memcpy(body + offset, &value, sizeof value);
}

static uint8_t reset_cause(void) {
    if (reset_flags & _BV(WDRF)) return WATCHDOG;
    if (reset_flags & _BV(BORF)) return BROWN_OUT;
    if (reset_flags & _BV(EXTRF)) return EXTERNAL;
    return POWER_ON;
}

static void send_info(void) {
    uint8_t *body = reply_body;
    uint8_t n = 0;
    body[n++] = PROTOCOL_VERSION;
    body[n++] = rig->kind;
    body[n++] = 0; /* firmware 0.2.0 */
    body[n++] = 2;
    body[n++] = 0;
    put_u32(body + n, rig->period_us);
    n += 4;
    body[n++] = rig->channel_count;
    for (uint8_t c = 0; c < rig->channel_count; c++) {
        for (uint8_t t = 0; t < 2; t++) {
            uint8_t length = (uint8_t)strlen(rig->channels[c][t]);
            body[n++] = length;
            memcpy(body + n, rig->channels[c][t], length);
            n = (uint8_t)(n + length);
        }
    }
    body[n++] = reset_cause();
    frame_send(INFO, body, n);
}

/* A run ends (`how`: enum run_end): outputs safe first, then the words. DONE waits for the
 * samples not yet sent; a STOP drops them; an end the device chose (the host's silence, an
 * error) drops them and says `why` in an ERROR naming the START. */
static void end_run(uint8_t how, const char *why) {
    rig->safe();
    probe_end();
    running = finished = 0;
    ended = how;
    draining = how == ENDED_DONE;
    if (!draining) ring_tail = ring_head;
    if (how == ENDED_HOST || how == ENDED_ERROR) send_error(run_seq, STOPPED, why);
}

static void start(const struct command *c) {
    if ((running || draining) && c->seq != run_seq) {
        send_error(c->seq, BUSY, "a run is going on; STOP it first");
        return;
    }
    if (c->length != 8 && c->length != 10) {
        send_error(c->seq, BAD_FRAME, "START takes a duration, a seed and host_timeout_ms");
        return;
    }
    if (!have_last_start || c->seq != last_start) {
        float duration = read_float(c->body, 0);
        uint32_t seed = 0;
        for (uint8_t k = 0; k < 4; k++) seed |= (uint32_t)c->body[4 + k] << (8 * k);
        uint16_t timeout = HOST_TIMEOUT_MS;
        if (c->length == 10) timeout = (uint16_t)(c->body[8] | (c->body[9] << 8));
        if (timeout < MIN_HOST_TIMEOUT_MS || timeout > MAX_HOST_TIMEOUT_MS) {
            send_error(c->seq, BAD_VALUE, "START: host_timeout_ms must be 20-60000");
            return;
        }
        const char *why = "";
        ring_tail = ring_head;
        samples = 0;
        finished = draining = 0;
        uint8_t code = rig->start(duration, &why);
        if (code) {
            rig->safe();
            send_error(c->seq, code, why);
            return;
        }
        probe_run(seed); /* right after the control timer starts: the plant's time 0 */
        running = 1;
        ended = NOT_ENDED;
        host_timeout_ms = timeout;
        heard_ms = rig_clock_ms();
        run_seq = last_start = c->seq;
        have_last_start = 1;
    }
    send_ack(c->seq);
}

static void status(uint16_t seq) {
    uint8_t body[10] = {(uint8_t)(seq & 0xFF), (uint8_t)(seq >> 8), running || draining};
    uint32_t taken;
    ATOMIC_BLOCK(ATOMIC_RESTORESTATE) { taken = samples; }
    put_u32(body + 3, taken);
    uint16_t lost = uart_overruns();
    body[7] = (uint8_t)(lost & 0xFF);
    body[8] = (uint8_t)(lost >> 8);
    body[9] = ended;
    frame_send(ACK, body, 10);
}

static void get(const struct command *c) {
    uint8_t *body = reply_body;
    if (c->length != 1) {
        send_error(c->seq, BAD_FRAME, "GET takes the type of a SET_ command (u8)");
        return;
    }
    uint8_t n = rig->setting(c->body[0], body + 2);
    if (n == 0xFF) {
        send_error(c->seq, UNKNOWN, "this rig has no such setting");
        return;
    }
    body[0] = (uint8_t)(c->seq & 0xFF);
    body[1] = (uint8_t)(c->seq >> 8);
    frame_send(ACK, body, (uint8_t)(n + 2));
}

static void handle(const struct command *c) {
    switch (c->kind) {
    case HELLO: /* a new session: its START may reuse the last one's seq (a new run) */
        if (!running && !draining) have_last_start = 0;
        send_info();
        return;
    case START:
        start(c);
        return;
    case STOP:
        if (running) end_run(ENDED_STOP, 0);
        else rig->safe();
        draining = 0;
        ring_tail = ring_head;
        send_ack(c->seq);
        return;
    case STREAM:
        if (c->length != 2) {
            send_error(c->seq, BAD_FRAME, "STREAM takes a decimation (u16)");
            return;
        }
        decimation = (uint16_t)(c->body[0] | (c->body[1] << 8));
        send_ack(c->seq);
        return;
    case STATUS:
        status(c->seq);
        return;
    case GET:
        get(c);
        return;
    default:
        if (running || draining) {
            send_error(c->seq, BUSY, "settings wait for the rig at rest; STOP the run first");
            return;
        }
        const char *why = "";
        uint8_t code = rig->configure(c->kind, c->body, c->length, &why);
        if (code) send_error(c->seq, code, why);
        else send_ack(c->seq);
    }
}

/* Send the oldest sample not sent yet if the send queue has room for it now (a run never
 * waits on the line); 1 if one was taken. Device time: the sample's index times the period,
 * in µs modulo 2^32 (it wraps every 71.6 minutes; the host unwraps it). */
static uint8_t send_sample(void) {
    if (ring_tail == ring_head) return 0;
    const struct sample *s = &ring[ring_tail];
    uint8_t length = (uint8_t)(4 + 4 * rig->channel_count);
    /* (A 32-bit remainder costs some 600 cycles: not for the default, every sample.) */
    if (decimation == 1 || (decimation && s->index % decimation == 0)) {
        /* Type, seq, CRC, COBS and delimiter besides; and the room a reply needs kept. */
        if (uart_space() < (uint16_t)(length + 7 + REPLY_ROOM)) return 0;
        static uint8_t body[4 + 4 * MAX_CHANNELS];
        float values[MAX_CHANNELS];
        memcpy(values, s->values, sizeof(float) * rig->channel_count);
        if (rig->format) rig->format(values);
        put_u32(body, s->index * rig->period_us);
        memcpy(body + 4, values, sizeof(float) * rig->channel_count);
        frame_send(TELEMETRY, body, length);
    }
    ring_tail = (uint8_t)((ring_tail + 1) % RING);
    return 1;
}

/* The bytes that came, in batches shorter than any frame (7 bytes), so that one ends in a
 * batch at most; until a command has been answered or RECEIVE_BATCH bytes taken (the control
 * step goes first), and only with room for a reply (the main loop never waits on the line
 * during a run). Several batches a pass, so that a pass's own cost is spread over many bytes:
 * at full line rate the receive interrupt takes half of each byte's 160 cycles. How many it
 * took. */
static uint8_t receive(void) {
    if (uart_space() < REPLY_ROOM) return 0;
    struct command command;
    uint8_t bytes[6], took = 0, answered = 0;
    while (!answered && took < RECEIVE_BATCH) {
        uint8_t n = uart_take(bytes, sizeof bytes);
        if (!n) break;
        took = (uint8_t)(took + n);
        for (uint8_t k = 0; k < n; k++) {
            if (frame_receive(bytes[k], &command)) {
                heard_ms = rig_clock_ms();
                handle(&command); /* its reply fits: the room was there */
                answered = 1;
            }
        }
    }
    return took;
}

/* The run's checks, once a main-loop pass: its control step, its end, the host's silence. */
static void run_checks(void) {
    if (stalled) { /* the watchdog's interrupt put the outputs off: the main loop was late */
        stalled = 0;
        watchdog_on();
        if (running) end_run(ENDED_ERROR, "the main loop stalled past the watchdog's 32 ms");
    }
    if (!running) return;
    rig_event = 0;
    const char *reason = rig->control();
    if (reason) end_run(ENDED_ERROR, reason);
    else if (finished) end_run(ENDED_DONE, 0);
    else if ((uint16_t)(rig_clock_ms() - heard_ms) >= host_timeout_ms)
        end_run(ENDED_HOST, "no frame from the host within host_timeout_ms; outputs off");
}

void rig_serve(const struct rig *program) {
    rig = program;
    rig->safe();
    OCR0A = 249; /* TOP first (simavr reads it as the clock starts): 16 MHz / 64 / 250 */
    TCCR0A = _BV(WGM01);
    TCCR0B = _BV(CS01) | _BV(CS00);
    TIMSK0 = _BV(OCIE0A);
    watchdog_on();
    sei();
    /* A device that starts says so, unasked (docs/protocol.md, handshake step 4): a delimiter
     * ends the frame a reset may have cut, then INFO, the first of its sequence numbers. */
    static const uint8_t delimiter = 0;
    uart_write(&delimiter, 1);
    send_info();
    set_sleep_mode(SLEEP_MODE_IDLE);
    for (;;) {
        wdt_reset();
        uart_alive();
        run_checks();
        if (receive()) continue;
        if (send_sample()) continue;
        if (draining && ring_tail == ring_head) {
            uint8_t body[6] = {(uint8_t)(run_seq & 0xFF), (uint8_t)(run_seq >> 8)};
            put_u32(body + 2, samples); /* the run is over: no interrupt changes it */
            draining = 0;
            frame_send(DONE, body, 6);
        }
        /* Nothing to do: sleep until an interrupt (a byte, a sample, the clock's tick). A
         * sample that waits for room on the line does not keep the loop awake: the send
         * queue's interrupt wakes it as room comes. Checked with interrupts off: what an
         * interrupt leaves after this cannot be slept over. */
        cli();
        if (!uart_pending() && !rig_event && !stalled && !finished &&
            (ring_tail == ring_head || uart_space() < REPLY_ROOM + 4 + 4 * MAX_CHANNELS + 7)) {
            sleep_enable();
            sei();
            sleep_cpu();
            sleep_disable();
        }
        sei();
    }
}
