/*
 * hd_stand_in_control.h - test control API of the stand-in libHD.so.
 *
 * Plain C. Every function is exported by the stand-in with C linkage; a test
 * dlopen()s the same libHD.so the code under test loads and dlsym()s these.
 * All functions may be called from any thread while the scheduler runs,
 * except where noted. HDenum / HDerror values are passed as unsigned int.
 *
 * Units and frames: positions mm, velocities mm/s, forces N, times s;
 * HDAPI's device frame (x right, y up, z towards the user), origin at the
 * centre of the usable workspace.
 */
#ifndef HD_STAND_IN_CONTROL_H
#define HD_STAND_IN_CONTROL_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/* One record per servo tick (index == tick index since the last reset). */
struct hd_stand_in_frame_record {
  long tick;                /* servo tick index, 0 = first tick after reset        */
  double device_time_s;     /* stand-in device clock at tick start (large offset)  */
  double position_mm[3];    /* HD_CURRENT_POSITION reported in this tick's frames   */
  double velocity_mm_s[3];  /* HD_CURRENT_VELOCITY reported in this tick's frames   */
  int buttons;              /* HD_CURRENT_BUTTONS reported                         */
  int inkwell_switch;       /* HD_CURRENT_INKWELL_SWITCH reported (raw value)      */
  int frames;               /* hdBeginFrame/hdEndFrame pairs completed this tick   */
  int position_read;        /* HD_CURRENT_POSITION read inside a frame this tick   */
  int force_set;            /* HD_CURRENT_FORCE set inside a frame this tick       */
  double force_set_n[3];    /* last force set this tick (0 if none)                */
  int force_output;         /* 1 if a force went to the motors this tick           */
  double force_output_n[3]; /* force applied at hdEndFrame (0 when not output)     */
  unsigned int first_error; /* first HDerror pushed on the servo thread this tick  */
  int error_count;          /* errors pushed on the servo thread this tick         */
  long late_us;             /* tick start minus its deadline, microseconds         */
};

/* Fault kinds for hd_stand_in_inject(kind, tick, value). A fault fires at the
 * first servo tick whose index is >= tick. */
enum hd_stand_in_fault {
  HD_STAND_IN_FAULT_LINK_LOST = 1,       /* every later frame pushes HD_COMM_ERROR, pose
                                            freezes, forces not output             */
  HD_STAND_IN_FAULT_FORCE_LIMIT = 2,     /* HD_EXCEEDED_MAX_FORCE at that tick, zero force,
                                            HD_FORCE_OUTPUT disabled                */
  HD_STAND_IN_FAULT_SCHEDULER_FULL = 3,  /* next (int)value schedule calls (min 1) made once
                                            ticks >= tick fail: HD_SCHEDULER_FULL  */
  HD_STAND_IN_FAULT_SLOW_FRAME = 4,      /* that tick starts value ms late             */
  HD_STAND_IN_FAULT_INIT_FAILURE = 5,    /* = hd_stand_in_fail_init(HD_COMM_CONFIG_ERROR) */
  HD_STAND_IN_FAULT_INVALID_LICENSE = 6, /* = hd_stand_in_fail_init(HD_INVALID_LICENSE) */
  HD_STAND_IN_FAULT_LINK_RESTORED = 7    /* ends a LINK_LOST from that tick on         */
};

/* Rule-violation kinds counted by hd_stand_in_violation_count(kind). */
enum hd_stand_in_violation {
  HD_STAND_IN_VIOLATION_READ_OUTSIDE_FRAME = 1,  /* HD_CURRENT_x / HD_LAST_x read on the servo
                                                    thread with no open frame (HD_INVALID_OPERATION) */
  HD_STAND_IN_VIOLATION_SET_OUTSIDE_FRAME = 2,   /* HD_CURRENT_FORCE set on the servo thread
                                                    with no open frame (HD_INVALID_OPERATION) */
  HD_STAND_IN_VIOLATION_WRONG_THREAD = 3,        /* frame state read/set or hdBeginFrame /
                                                    hdEndFrame off the servo thread        */
  HD_STAND_IN_VIOLATION_NESTED_BEGIN = 4,        /* hdBeginFrame inside a frame (HD_ILLEGAL_BEGIN) */
  HD_STAND_IN_VIOLATION_END_WITHOUT_BEGIN = 5,   /* hdEndFrame outside a frame (HD_ILLEGAL_END) */
  HD_STAND_IN_VIOLATION_FRAME_LEFT_OPEN = 6,     /* tick ended with a frame open (HD_FRAME_ERROR) */
  HD_STAND_IN_VIOLATION_BLOCKING_ON_SERVO = 7,   /* hdScheduleSynchronous, hdStopScheduler or
                                                    hdWaitForCompletion(HD_WAIT_INFINITE) called
                                                    from a callback (HD_INVALID_OPERATION) */
  HD_STAND_IN_VIOLATION_SECOND_FRAME_IN_TICK = 8 /* only with strict_one_frame: a second frame
                                                    in one tick (HD_ILLEGAL_BEGIN)          */
};

/* HDErrorInfo.internalErrorCode values pushed by the stand-in. */
#define HD_STAND_IN_INTERNAL_API 0               /* plain API misuse (bad enum, value, handle) */
#define HD_STAND_IN_INTERNAL_VIOLATION_BASE 1000 /* + enum hd_stand_in_violation               */
#define HD_STAND_IN_INTERNAL_FAULT_BASE 2000     /* + enum hd_stand_in_fault (injected)         */
#define HD_STAND_IN_INTERNAL_FORCE_MODEL 3000    /* client force above HD_NOMINAL_MAX_FORCE    */

/* ---- lifecycle and configuration ---- */
int hd_stand_in_reset(void); /* stops the scheduler, forgets callbacks, device, errors, log,
                                faults, hand, counters; restores defaults. 0, or -1 if called
                                from a scheduler callback */
int hd_stand_in_configure_log(size_t capacity);              /* ring of the last `capacity` ticks (default
                                             32768); allocates; 0, or -1 while the scheduler runs / capacity 0 */
void hd_stand_in_set_device_name(const char* name);          /* name hdInitDevice accepts besides NULL
                                         and "Default Device" (default "Default Device") */
void hd_stand_in_set_clock_offset(double seconds);           /* device clock = CLOCK_MONOTONIC + offset
                                                                (default 1600 s) */
double hd_stand_in_device_time(void);                        /* device clock now, s */
void hd_stand_in_set_force_output_at_init(int enabled);      /* HD_FORCE_OUTPUT after hdInitDevice
                                                                (default 0: client must hdEnable) */
void hd_stand_in_set_inkwell_polarity(int docked_reads_one); /* default 0: switch reads 0 when
                                                                docked, 1 when out */
void hd_stand_in_set_strict_one_frame(int on);               /* 1: a second frame in one tick is illegal */

/* ---- the hand ---- */
int hd_stand_in_set_path(const double* t_s, const double* xyz_mm, size_t n);            /* n points,
                       xyz_mm = n*3 values (NaN or +-inf allowed: a garbled reading, held over
                       its segment); t finite, non-decreasing; n = 0 clears (pen at origin). 0 or -1 */
void hd_stand_in_set_square_wave(int axis, double amplitude_mm, int half_period_ticks); /*
            adds 0 for half_period ticks, then +amplitude for half_period ticks, ...;
            counted from the first tick after the call; amplitude 0 or half_period <= 0 off */
void hd_stand_in_set_docked(int docked);
void hd_stand_in_set_buttons(int bits); /* HD_DEVICE_BUTTON_x bits */

/* ---- calibration ---- */
void hd_stand_in_set_calibration(unsigned int state, int styles); /* state: HD_CALIBRATION_OK /
            _NEEDS_UPDATE / _NEEDS_MANUAL_INPUT (other values ignored); styles: bitmask of
            HD_CALIBRATION_ENCODER_RESET|AUTO|INKWELL, < 0 keeps the current one */

/* ---- faults ---- */
int hd_stand_in_inject(int fault_kind, long tick, double value); /* 0, or -1 (bad kind/full) */
void hd_stand_in_fail_init(unsigned int code);                   /* hdInitDevice pushes `code` and returns
                                                                    HD_INVALID_HANDLE until called with 0 */

/* ---- observation ---- */
size_t hd_stand_in_frame_count(void); /* ticks logged since reset (== hd_stand_in_ticks()) */
size_t hd_stand_in_frame_first(void); /* oldest tick index still held by the ring */
int hd_stand_in_frame(size_t i, struct hd_stand_in_frame_record* out); /* 1 if tick i is held */
long hd_stand_in_violations(void);                                     /* all kinds */
long hd_stand_in_violation_count(int kind);
long hd_stand_in_ticks(void);                         /* completed servo ticks since reset */
int hd_stand_in_wait_ticks(long n, double timeout_s); /* 1 once ticks >= n, 0 on timeout */
int hd_stand_in_scheduler_running(void);
int hd_stand_in_scheduled_count(void); /* callbacks currently scheduled */
int hd_stand_in_device_initialized(void);
int hd_stand_in_link_lost(void);
int hd_stand_in_error_depth(void); /* entries on the HDAPI error stack */

#ifdef __cplusplus
}
#endif

#endif /* HD_STAND_IN_CONTROL_H */
