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
 * pressure: partial pressures need chamber pressure sensors the book's rig does not have.
 *
 * The tick's interrupt only plays the valve events the main loop scheduled at START, as a
 * timer's compare output would: one event a tick at most, the coils of all the chambers that
 * change then, precomputed, so that it stays short; everything else (the sensor's frames
 * into samples, the checks) runs in the main loop. Safe state: pump off, every chamber
 * venting. A run ends in it with an error when the sensor has sent no frame for
 * SENSOR_TIMEOUT_MS. */
#include <avr/interrupt.h>
#include <avr/io.h>
#include <avr/pgmspace.h>
#include <math.h>
#include <util/atomic.h>

#ifdef FILL_TABLE /* make FILL_TABLE=fill.h: another actuator's (tools/fill_table.py --plant) */
#include FILL_TABLE
#else
#include "fill_table.h"
#endif
#include "probe.h"
#include "protocol.h"
#include "rig.h"
#include "uart.h"

RIG_PROGRAM("six_chamber");

#define TICK_HZ 10000.0f /* the valve sequencer's tick */
#define TICKS 1600       /* CPU cycles per tick */
#define RATE_HZ 100.0f   /* the sensor's frames */
#define CHAMBERS 6
#define SHAPE_ACTUATION 3 /* programs.py's Shape.ACTUATION */
#define MAX_EVENTS 8
#define DEG (180.0f / (float)M_PI)
#define SENSOR_TIMEOUT_MS 50 /* five of the sensor's periods */
enum mode { VENT = 0, HOLD = 1, FILL = 2 }; /* plants/six_chamber_sim.py's valve positions */

static const char *const channels[][2] = {{"bend_x", "deg"}, {"bend_y", "deg"}};

/* Settings: the actuation (side [deg], gauge pressure [Pa], hold [s]) and the damping
 * policy (δ, start [s], length [s]). */
static float side = 0.0f, gauge = SUPPLY_PA, hold = 1.0f;
static float delta = 0.0f, pulse_start = 0.0f, pulse_length = 0.0f;

/* Valve coils to set on the two ports: which (mask) and which of them on (bits). */
struct coils {
    uint8_t mask_a, bits_a; /* PORTA: chambers 0-3 */
    uint8_t mask_c, bits_c; /* PORTC: chambers 4-5 */
};

/* The run: valve events in tick order (one a tick), the tick, the sensor's samples to take;
 * every chamber venting (the safe state's coils, set up by main). */
struct event {
    uint32_t tick;
    struct coils coils;
};
static struct event events[MAX_EVENTS];
static uint8_t event_count, next_event;
static volatile uint32_t tick;
static uint32_t samples_left;
static uint16_t frame_ms; /* when the sensor's last frame was taken (rig_clock_ms) */
static struct coils venting;
static volatile uint8_t live; /* the run's valves may be driven (safe() ends that) */

/* The sensor's frames, filled by the Serial1 interrupt in turn: the one ready for the main
 * loop is not written until it has been taken (no copy in the interrupt). */
static uint8_t frames[2][12];
static volatile uint8_t frame_ready, ready_at;

/* A chamber's valve coils (fill, vent) in `mode` added to `to` (replacing that chamber's). */
static void add_coils(struct coils *to, uint8_t chamber, uint8_t mode) {
    uint8_t fill = mode == FILL, vent = mode == VENT;
    if (chamber < 4) {
        uint8_t pair = (uint8_t)(3 << (2 * chamber));
        to->mask_a |= pair;
        to->bits_a = (uint8_t)((to->bits_a & ~pair) | fill << (2 * chamber) | vent << (2 * chamber + 1));
        return;
    }
    uint8_t at = (uint8_t)(7 - 2 * (chamber - 4)); /* D30 = PC7, D31 = PC6, D32 = PC5, D33 = PC4 */
    uint8_t pair = (uint8_t)(3 << (at - 1));
    to->mask_c |= pair;
    to->bits_c = (uint8_t)((to->bits_c & ~pair) | fill << at | vent << (at - 1));
}

/* Coils set: a read-modify-write of each port (the caller keeps interrupts out), some 20
 * cycles. */
static void apply(const struct coils *c) {
    PORTA = (uint8_t)((PORTA & ~c->mask_a) | c->bits_a);
    PORTC = (uint8_t)((PORTC & ~c->mask_c) | c->bits_c);
}

/* The 10 kHz tick: the event that is due, its coils precomputed at START. With interrupts on
 * from its first instruction (ISR_NOBLOCK: the 32-bit tick's prologue alone is some 60
 * cycles), the coils set atomically and only while the run is live: the watchdog's safe(),
 * nested in it, is not undone. */
ISR(TIMER1_COMPA_vect, ISR_NOBLOCK) {
    probe_busy();
    uint32_t now = ++tick;
    if (next_event < event_count && events[next_event].tick <= now) {
        ATOMIC_BLOCK(ATOMIC_FORCEON) {
            if (live) apply(&events[next_event].coils);
        }
        next_event++;
    }
    probe_idle();
}

/* Serial1: A5 5A, twelve bytes (roll, pitch, yaw float32), their byte sum. */
ISR(USART1_RX_vect) {
    static uint8_t at, sum, filling;
    uint8_t byte = UDR1;
    if (at == 0) at = byte == 0xA5;
    else if (at == 1) at = byte == 0x5A ? 2 : (byte == 0xA5);
    else if (at < 14) frames[filling][at - 2] = byte, sum = (uint8_t)(at == 2 ? byte : sum + byte), at++;
    else {
        if (byte == sum && !frame_ready) ready_at = filling, filling ^= 1, frame_ready = 1, rig_event = 1;
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

/* A chamber's valves to `mode` at `seconds` into the run: into the event of that tick (a
 * later call for the same chamber and tick wins), or a new one in tick order. */
static void add_event(float seconds, uint8_t chamber, uint8_t mode) {
    uint32_t at = tick_at(seconds);
    uint8_t k = 0;
    while (k < event_count && events[k].tick < at) k++;
    if (k == event_count || events[k].tick != at) {
        for (uint8_t j = event_count++; j > k; j--) events[j] = events[j - 1];
        events[k] = (struct event){at, {0, 0, 0, 0}};
    }
    add_coils(&events[k].coils, chamber, mode);
}

/* The run's main-loop work: a sensor frame into a sample, the bending vector of the top's
 * tilt; a sensor that went quiet ends the run. */
static const char *control(void) {
    if (!frame_ready) {
        if ((uint16_t)(rig_clock_ms() - frame_ms) > SENSOR_TIMEOUT_MS)
            return "no frame from the orientation sensor for 50 ms";
        return 0;
    }
    frame_ms = rig_clock_ms();
    const uint8_t *frame = frames[ready_at];
    float roll = read_float(frame, 0) / DEG, pitch = read_float(frame, 4) / DEG;
    float yaw = read_float(frame, 8) / DEG;
    frame_ready = 0; /* read: the interrupt may fill it again */
    /* The top's normal R ẑ for R = Rz(yaw) Ry(pitch) Rx(roll) (intrinsic Z-Y-X). */
    float cr = cosf(roll), sr = sinf(roll), sp = sinf(pitch), cy = cosf(yaw), sy = sinf(yaw);
    float nx = cr * sp * cy + sr * sy, ny = cr * sp * sy - sr * cy, nz = cr * cosf(pitch);
    float horizontal = sqrtf(nx * nx + ny * ny);
    float scale = horizontal > 0.0f ? atan2f(horizontal, nz) / horizontal : 1.0f;
    float *bend = rig_slot();
    bend[0] = nx * scale * DEG, bend[1] = ny * scale * DEG;
    rig_sample();
    if (--samples_left == 0) rig_done();
    return 0;
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
    frame_ms = rig_clock_ms();
    struct coils first = venting; /* the side filling from the start, the others venting */
    add_coils(&first, chamber, FILL);
    ATOMIC_BLOCK(ATOMIC_RESTORESTATE) {
        apply(&first);
        live = 1;
        frame_ready = 0;
        tick = 0;
        PORTH |= _BV(PH5); /* the pump */
        TCNT1 = 0;
        TIFR1 = _BV(OCF1A);
        TIMSK1 = _BV(OCIE1A);
    }
    return 0;
}

/* Pump off and every chamber venting, no more valve events, none pending: in one atomic
 * write of some 40 cycles (tools/interrupts_off.py). */
static void safe(void) {
    ATOMIC_BLOCK(ATOMIC_RESTORESTATE) {
        TIMSK1 = 0;
        TIFR1 = _BV(OCF1A);
        live = 0;
        PORTH &= (uint8_t)~_BV(PH5);
        apply(&venting);
    }
}

/* GET: the actuation and the damping policy as SET_REFERENCE and SET_DAMPING carry them. */
static uint8_t setting(uint8_t kind, uint8_t *body) {
    if (kind == SET_REFERENCE) {
        body[0] = SHAPE_ACTUATION;
        body[1] = 3;
        write_float(body, 2, side);
        write_float(body, 6, gauge);
        write_float(body, 10, hold);
        return 14;
    }
    if (kind == SET_DAMPING) {
        write_float(body, 0, delta);
        write_float(body, 4, pulse_start);
        write_float(body, 8, pulse_length);
        return 12;
    }
    return 0xFF;
}

static const struct rig six_chamber = {.kind = 2, .period_us = 10000, .channel_count = 2,
                                       .channels = channels, .configure = configure,
                                       .setting = setting, .start = start, .safe = safe,
                                       .control = control};

int main(void) {
    uart_init();
    DDRA = 0xFF;                                           /* valves of chambers 0-3 */
    DDRC |= _BV(PC7) | _BV(PC6) | _BV(PC5) | _BV(PC4);    /* valves of chambers 4-5 */
    DDRH |= _BV(PH5);                                      /* the pump: D8 */
    UCSR1A = _BV(U2X1);                                    /* Serial1: the sensor */
    UBRR1 = 16;                                            /* 117 647 baud, 2 % off 115 200 */
    UCSR1B = _BV(RXEN1) | _BV(RXCIE1);
    UCSR1C = _BV(UCSZ11) | _BV(UCSZ10);
    for (uint8_t c = 0; c < CHAMBERS; c++) add_coils(&venting, c, VENT);
    OCR1A = TICKS - 1; /* TOP first: the timer starts with its clock */
    TCCR1B = _BV(WGM12) | _BV(CS10); /* CTC: the 10 kHz tick */
    rig_serve(&six_chamber);
}
