/* The command loop and the run's telemetry (rig.h). */
#include "rig.h"

#include <avr/interrupt.h>
#include <avr/sleep.h>
#include <string.h>
#include <util/atomic.h>

#include "probe.h"
#include "protocol.h"
#include "uart.h"

#define RING 8 /* samples between the control interrupt and the main loop */

struct sample {
    uint32_t index;
    float values[MAX_CHANNELS];
};

static struct sample ring[RING];
static volatile uint8_t ring_head, ring_tail; /* head: interrupt's; tail: main loop's */
static volatile uint32_t samples;             /* of the run going on, or of the last one */
static volatile uint8_t finished;             /* the interrupt's word that the run is over */
static uint8_t channel_count;

void adc_start(uint8_t channel) {
    ADMUX = _BV(REFS0) | channel;
    ADCSRA = _BV(ADEN) | _BV(ADPS2) | _BV(ADPS1) | _BV(ADPS0); /* 16 MHz / 128 */
    ADCSRA |= _BV(ADIE) | _BV(ADSC);
}

void rig_sample(const float *values) {
    uint8_t next = (uint8_t)((ring_head + 1) % RING);
    if (next != ring_tail) { /* full: the sample is not sent (the host sees the gap) */
        ring[ring_head].index = samples;
        memcpy(ring[ring_head].values, values, sizeof(float) * channel_count);
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

static void put_u32(uint8_t *out, uint32_t value) {
    for (uint8_t k = 0; k < 4; k++) out[k] = (uint8_t)(value >> (8 * k));
}

static void send_info(const struct rig *rig) {
    static uint8_t body[MAX_FRAME - 5];
    uint8_t n = 0;
    body[n++] = PROTOCOL_VERSION;
    body[n++] = rig->kind;
    body[n++] = 0; /* firmware 0.1.0 */
    body[n++] = 1;
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
    frame_send(INFO, body, n);
}

/* Run state the main loop keeps: whether one is going on, its START's seq, the last START
 * carried out (a START sent again is only acknowledged), the decimation. */
static uint8_t running;
static uint16_t run_seq, last_start;
static uint8_t have_last_start;
static uint16_t decimation = 1;

static void end_run(const struct rig *rig) {
    rig->stop();
    running = 0;
    finished = 0;
    ring_tail = ring_head; /* what was not sent is dropped */
    probe_end();
}

static void start(const struct rig *rig, const struct command *c) {
    if (running && c->seq != run_seq) {
        send_error(c->seq, BUSY, "a run is going on; STOP it first");
        return;
    }
    if (c->length != 8) {
        send_error(c->seq, BAD_FRAME, "START takes a duration and a seed");
        return;
    }
    if (!have_last_start || c->seq != last_start) {
        float duration = read_float(c->body, 0);
        uint32_t seed = 0;
        for (uint8_t k = 0; k < 4; k++) seed |= (uint32_t)c->body[4 + k] << (8 * k);
        const char *why = "";
        ring_tail = ring_head;
        samples = 0;
        finished = 0;
        uint8_t code = rig->start(duration, &why);
        if (code) {
            send_error(c->seq, code, why);
            return;
        }
        probe_run(seed); /* right after the control timer starts: the plant's time 0 */
        running = 1;
        run_seq = last_start = c->seq;
        have_last_start = 1;
    }
    send_ack(c->seq);
}

static void handle(const struct rig *rig, const struct command *c) {
    uint8_t body[7];
    switch (c->kind) {
    case HELLO:
        send_info(rig);
        return;
    case START:
        start(rig, c);
        return;
    case STOP:
        end_run(rig);
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
        body[0] = (uint8_t)(c->seq & 0xFF);
        body[1] = (uint8_t)(c->seq >> 8);
        body[2] = running;
        ATOMIC_BLOCK(ATOMIC_RESTORESTATE) { put_u32(body + 3, samples); }
        frame_send(ACK, body, 7);
        return;
    default:
        if (running) {
            send_error(c->seq, BUSY, "settings wait for the rig at rest; STOP the run first");
            return;
        }
        const char *why = "";
        uint8_t code = rig->configure(c->kind, c->body, c->length, &why);
        if (code) send_error(c->seq, code, why);
        else send_ack(c->seq);
    }
}

/* Send the oldest sample not sent yet; 1 if there was one. */
static uint8_t send_sample(const struct rig *rig) {
    if (ring_tail == ring_head) return 0;
    const struct sample *s = &ring[ring_tail];
    if (decimation && s->index % decimation == 0) {
        static uint8_t body[4 + 4 * MAX_CHANNELS];
        float values[MAX_CHANNELS];
        memcpy(values, s->values, sizeof(float) * rig->channel_count);
        if (rig->format) rig->format(values);
        put_u32(body, s->index * rig->period_us);
        memcpy(body + 4, values, sizeof(float) * rig->channel_count);
        frame_send(TELEMETRY, body, (uint8_t)(4 + 4 * rig->channel_count));
    }
    ring_tail = (uint8_t)((ring_tail + 1) % RING);
    return 1;
}

void rig_serve(const struct rig *rig) {
    channel_count = rig->channel_count;
    rig->stop();
    sei();
    /* A device that starts says so, unasked (docs/protocol.md, handshake step 4): a delimiter
     * ends the frame a reset may have cut, then INFO, the first of its sequence numbers. */
    static const uint8_t delimiter = 0;
    uart_write(&delimiter, 1);
    send_info(rig);
    set_sleep_mode(SLEEP_MODE_IDLE);
    struct command command;
    uint8_t byte;
    for (;;) {
        uint8_t busy = 0;
        while (uart_read(&byte)) {
            busy = 1;
            if (frame_receive(byte, &command)) handle(rig, &command);
        }
        if (running) {
            if (rig->background) rig->background();
            busy |= send_sample(rig);
            if (finished && ring_tail == ring_head) {
                uint8_t body[6] = {(uint8_t)(run_seq & 0xFF), (uint8_t)(run_seq >> 8)};
                put_u32(body + 2, samples);
                end_run(rig);
                frame_send(DONE, body, 6);
            }
        }
        if (busy) continue;
        /* Nothing to do: sleep until an interrupt (a byte, the control timer). */
        cli();
        if (!uart_pending() && ring_tail == ring_head && !finished) {
            sleep_enable();
            sei();
            sleep_cpu();
            sleep_disable();
        }
        sei();
    }
}
