/* The six-chamber rig's firmware (chapter 3): the valve sequence of a deactuation run and
 * the damping pulse (3.4), as articula's emulated rig runs them (rigs/six_chamber.py,
 * loops/six_chamber.py), with 0.1 ms timing; the orientation sensor read on Serial1.
 *
 * Each chamber's 3-port 3-position valve has two coils (fill, vent) through MOSFETs: chamber
 * i on D22 + 2i (fill) and D23 + 2i (vent), so PA0-PA7 for chambers 0-3 and PC7-PC4 for
 * chambers 4-5; neither coil on holds the chamber. The pump is on D8 during a run. A 10 kHz
 * tick (Timer1) carries out the run's valve events. The sensor (modelled: a fused IMU that
 * streams roll, pitch, yaw at 100 Hz on Serial1, 115 200 baud, as frames A5 5A, three
 * float32 [deg], a byte sum) gives a sample per frame: its tilt as the bending vector
 * (bend_x, bend_y) [deg]. The side must be a chamber's (a multiple of 60°) at the supply
 * pressure: partial pressures need chamber pressure sensors the book's rig does not have. */
#include <avr/interrupt.h>
#include <avr/io.h>
#include <avr/pgmspace.h>
#include <math.h>
#include <string.h>

#include "fill_table.h"
#include "probe.h"
#include "protocol.h"
#include "rig.h"
#include "uart.h"

#define TICK_HZ 10000.0f /* the valve sequencer's tick */
#define TICKS 1600       /* CPU cycles per tick */
#define RATE_HZ 100.0f   /* the sensor's frames */
#define CHAMBERS 6
#define SHAPE_ACTUATION 3 /* programs.py's Shape.ACTUATION */
#define MAX_EVENTS 8
#define DEG (180.0f / (float)M_PI)
enum mode { VENT = 0, HOLD = 1, FILL = 2 }; /* plants/six_chamber_sim.py's valve positions */

static const char *const channels[][2] = {{"bend_x", "deg"}, {"bend_y", "deg"}};

/* Settings: the actuation (side [deg], gauge pressure [Pa], hold [s]) and the damping
 * policy (δ, start [s], length [s]). */
static float side = 0.0f, gauge = SUPPLY_PA, hold = 1.0f;
static float delta = 0.0f, pulse_start = 0.0f, pulse_length = 0.0f;

/* The run: valve events in tick order, the tick, the sensor's samples to take. */
struct event {
    uint32_t tick;
    uint8_t chamber, mode;
};
static struct event events[MAX_EVENTS];
static uint8_t event_count, next_event;
static volatile uint32_t tick;
static uint32_t samples_left;

/* The sensor's frame, filled by the Serial1 interrupt, taken by the main loop. */
static uint8_t frame[12];
static volatile uint8_t frame_ready;

/* A chamber's valve coils (fill, vent). */
static void set_valve(uint8_t chamber, uint8_t mode) {
    uint8_t fill = mode == FILL, vent = mode == VENT;
    if (chamber < 4) {
        uint8_t bits = (uint8_t)(fill << (2 * chamber) | vent << (2 * chamber + 1));
        PORTA = (uint8_t)((PORTA & ~(3 << (2 * chamber))) | bits);
    } else { /* D30 = PC7, D31 = PC6, D32 = PC5, D33 = PC4 */
        uint8_t at = (uint8_t)(7 - 2 * (chamber - 4));
        uint8_t bits = (uint8_t)(fill << at | vent << (at - 1));
        PORTC = (uint8_t)((PORTC & ~(3 << (at - 1))) | bits);
    }
}

ISR(TIMER1_COMPA_vect) {
    probe_busy();
    uint32_t now = ++tick;
    while (next_event < event_count && events[next_event].tick <= now) {
        set_valve(events[next_event].chamber, events[next_event].mode);
        next_event++;
    }
    probe_idle();
}

/* Serial1: A5 5A, twelve bytes (roll, pitch, yaw float32), their byte sum. */
ISR(USART1_RX_vect) {
    static uint8_t at, sum, buffer[12];
    uint8_t byte = UDR1;
    if (at == 0) at = byte == 0xA5;
    else if (at == 1) at = byte == 0x5A ? 2 : (byte == 0xA5);
    else if (at < 14) buffer[at - 2] = byte, sum = (uint8_t)(at == 2 ? byte : sum + byte), at++;
    else {
        if (byte == sum && !frame_ready) memcpy(frame, buffer, 12), frame_ready = 1;
        at = 0;
    }
}

/* The tick of a time [s], as the simulation applies an event: at the nearest 0.1 ms step. */
static uint32_t tick_at(float seconds) { return (uint32_t)ceilf(seconds * TICK_HZ - 0.5f); }

/* Valve open time [s] that fills a still chamber to `fraction` of the supply (fill table). */
static float fill_time(float fraction) {
    float at = fraction * 100.0f;
    uint8_t k = at >= FILL_STEPS ? FILL_STEPS - 1 : (uint8_t)at;
    float lo = pgm_read_float(&fill_seconds[k]), hi = pgm_read_float(&fill_seconds[k + 1]);
    return lo + (at - k) * (hi - lo);
}

static void add_event(float seconds, uint8_t chamber, uint8_t mode) {
    struct event e = {tick_at(seconds), chamber, mode};
    uint8_t k = event_count++;
    while (k > 0 && events[k - 1].tick > e.tick) events[k] = events[k - 1], k--; /* stable */
    events[k] = e;
}

/* Off the interrupts: a sensor frame into a sample, the bending vector of the top's tilt. */
static void background(void) {
    if (!frame_ready || !samples_left) return;
    float roll = read_float(frame, 0) / DEG, pitch = read_float(frame, 4) / DEG;
    float yaw = read_float(frame, 8) / DEG;
    frame_ready = 0;
    /* The top's normal R ẑ for R = Rz(yaw) Ry(pitch) Rx(roll) (intrinsic Z-Y-X). */
    float cr = cosf(roll), sr = sinf(roll), sp = sinf(pitch), cy = cosf(yaw), sy = sinf(yaw);
    float nx = cr * sp * cy + sr * sy, ny = cr * sp * sy - sr * cy, nz = cr * cosf(pitch);
    float horizontal = sqrtf(nx * nx + ny * ny);
    float scale = horizontal > 0.0f ? atan2f(horizontal, nz) / horizontal : 1.0f;
    float bend[2] = {nx * scale * DEG, ny * scale * DEG};
    rig_sample(bend);
    if (--samples_left == 0) rig_done();
}

static uint8_t configure(uint8_t kind, const uint8_t *body, uint8_t length, const char **why) {
    if (kind == SET_REFERENCE) {
        if (length != 14 || body[0] != SHAPE_ACTUATION || body[1] != 3) {
            *why = "the six-chamber rig runs an actuation program";
            return BAD_VALUE;
        }
        float s = read_float(body, 2), g = read_float(body, 6), h = read_float(body, 10);
        float chamber = s / 60.0f;
        if (!(fabsf(chamber - roundf(chamber)) < 1e-4f && g >= SUPPLY_PA * (1.0f - 1e-6f) &&
              g <= SUPPLY_PA * (1.0f + 1e-6f) && h >= 0.0f && h < 1e6f)) {
            *why = "this firmware fills a chamber's side (a multiple of 60 deg) at the supply";
            return BAD_VALUE;
        }
        side = s, gauge = g, hold = h;
        return 0;
    }
    if (kind == SET_DAMPING) {
        float d = length == 12 ? read_float(body, 0) : -1.0f;
        float start = read_float(body, 4), len = read_float(body, 8);
        if (length != 12 || !(d >= 0.0f && d <= 0.95f && start >= 0.0f && start < 1e6f &&
                              len >= 0.0f && len < 1e6f)) {
            *why = "SET_DAMPING: delta 0-0.95, start and length >= 0";
            return BAD_VALUE;
        }
        delta = d, pulse_start = start, pulse_length = len;
        return 0;
    }
    *why = "the six-chamber rig does not take this command";
    return UNKNOWN;
}

static uint8_t start(float duration, const char **why) {
    if (!(duration > hold && duration < 1e6f)) {
        *why = "the run ends before the vent";
        return BAD_VALUE;
    }
    /* The sensor's frames at 0, 10, ... ms through the run's end (as the simulation samples). */
    samples_left = (uint32_t)floorf(duration * RATE_HZ + 1e-3f) + 1;
    uint8_t chamber = (uint8_t)((int16_t)roundf(side / 60.0f) % CHAMBERS + CHAMBERS) % CHAMBERS;
    event_count = next_event = 0;
    add_event(hold, chamber, VENT); /* filled from the start (below), vented at the hold */
    if (delta > 0.0f) { /* (3.4): the opposite chamber to δ of the side's pressure */
        uint8_t opposite = (uint8_t)((chamber + CHAMBERS / 2) % CHAMBERS);
        float open = fill_time(delta * gauge / SUPPLY_PA), at = hold + pulse_start;
        add_event(at, opposite, FILL);
        add_event(at + open, opposite, HOLD);
        add_event(at + (pulse_length > open ? pulse_length : open), opposite, VENT);
    }
    for (uint8_t c = 0; c < CHAMBERS; c++) set_valve(c, c == chamber ? FILL : VENT);
    frame_ready = 0;
    tick = 0;
    PORTH |= _BV(PH5); /* the pump */
    TCNT1 = 0;
    TIFR1 = _BV(OCF1A);
    TIMSK1 = _BV(OCIE1A);
    return 0;
}

static void stop(void) {
    TIMSK1 = 0;
    samples_left = 0;
    PORTH &= (uint8_t)~_BV(PH5);
    for (uint8_t c = 0; c < CHAMBERS; c++) set_valve(c, VENT);
}

static const struct rig six_chamber = {.kind = 2, .period_us = 10000, .channel_count = 2,
                                       .channels = channels, .configure = configure,
                                       .start = start, .stop = stop,
                                       .background = background};

int main(void) {
    uart_init();
    DDRA = 0xFF;                                           /* valves of chambers 0-3 */
    DDRC |= _BV(PC7) | _BV(PC6) | _BV(PC5) | _BV(PC4);    /* valves of chambers 4-5 */
    DDRH |= _BV(PH5);                                      /* the pump: D8 */
    UCSR1A = _BV(U2X1);                                    /* Serial1: the sensor */
    UBRR1 = 16;                                            /* 117 647 baud, 2 % off 115 200 */
    UCSR1B = _BV(RXEN1) | _BV(RXCIE1);
    UCSR1C = _BV(UCSZ11) | _BV(UCSZ10);
    OCR1A = TICKS - 1; /* TOP first: the timer starts with its clock */
    TCCR1B = _BV(WGM12) | _BV(CS10); /* CTC: the 10 kHz tick */
    rig_serve(&six_chamber);
}
