/* The FMI rules of the rwadist wheel FMUs, in one place: the states of an instance, which calls each state allows,
 * where an error leads, what a refused call tells the host to do next, and the variables by value reference.
 * Included by the native FMU's wrapper layer (rwadist_wheel_instance.h, FMI 2.0 and 3.0) and by the pythonfmu FMU's
 * native layer (rwadist_fmu_native.c, FMI 2.0); it needs neither the model nor an FMI header.
 *
 * The tables are the standards' (co-simulation, no event mode, no asynchronous steps):
 *  - FMI 2.0.4, section 4.2.4 (the table of allowed calls and figure 11): instantiated, Initialization Mode,
 *    stepComplete ("stepping" here), terminated, error.  A call of an instance in instantiated, Initialization Mode
 *    or stepping that returns fmi2Error moves it to error; in terminated it stays (figure 11).  From error and
 *    terminated: the getters (values for debugging after an error), the FMU-state functions (fmi2SetFMUstate goes to
 *    the stored state), fmi2Reset, fmi2FreeInstance.
 *  - FMI 3.0.2, section 2.3 (common states) and 4.2 (Step Mode): Instantiated, Initialization Mode, Step Mode,
 *    Terminated; any fmi3Error in the super state "FMU State Settable" (all of them) moves it to Terminated.  The
 *    getters are allowed in every state (the start values in Instantiated), the FMU-state functions and fmi3Reset
 *    anywhere.
 * One documented leniency: an FMI 2.0 input may be set in instantiated (FMI 2.0 allows only variables with initial =
 * exact or approx there, which an input cannot have); FMI 3.0 allows it, the FMI 2.0 standard's own pseudocode sets
 * "all variable start values" before fmi2EnterInitializationMode, and fmpy's simulate_fmu sets an input's start value
 * there.  The value is the input's value at initialisation, as if set in Initialization Mode.
 * The Modelica Association's Reference FMUs allow the same calls, except that theirs also take fmi3Set{Type} in
 * Terminated (the standard lists only the getters there) and merge FMI 2.0's error state into terminated. */
#ifndef RWADIST_FMI_RULES_H
#define RWADIST_FMI_RULES_H
#include <stdio.h>
#include <string.h>

/* states; the numbers are stored in a serialized FMU state: keep them */
enum { ST_INSTANTIATED = 0, ST_INIT = 1, ST_STEP = 2, ST_TERMINATED = 3, ST_ERROR = 4, N_ST = 5 };
#define IN(s) (1u << (s))
#define ANY_STATE (IN(ST_INSTANTIATED) | IN(ST_INIT) | IN(ST_STEP) | IN(ST_TERMINATED) | IN(ST_ERROR))

/* the calls, by their row of the standards' tables */
typedef enum {
    RW_SETUP_EXPERIMENT, /* fmi2SetupExperiment (FMI 3.0: the arguments of fmi3EnterInitializationMode) */
    RW_ENTER_INIT,
    RW_EXIT_INIT,
    RW_DO_STEP,
    RW_TERMINATE,
    RW_RESET,
    RW_GET,           /* fmiXGet{Type} */
    RW_SET_INPUT,     /* fmiXSet{Type} of inputs only */
    RW_SET_PARAMETER, /* fmiXSet{Type} of a fixed parameter */
    RW_GET_STATUS,    /* fmi2Get{Type}Status */
    RW_FMU_STATE,     /* get, set, free, serialize, deserialize an FMU state */
    N_CALLS
} RwCall;

#define INIT_ON (IN(ST_INIT) | IN(ST_STEP) | IN(ST_TERMINATED) | IN(ST_ERROR))
/* RW_ALLOWED[fmi version - 2][call]: the states the call is allowed in */
static const unsigned RW_ALLOWED[2][N_CALLS] = {
    {IN(ST_INSTANTIATED), IN(ST_INSTANTIATED), IN(ST_INIT), IN(ST_STEP), IN(ST_STEP), ANY_STATE, INIT_ON,
     IN(ST_INSTANTIATED) | IN(ST_INIT) | IN(ST_STEP), IN(ST_INSTANTIATED) | IN(ST_INIT),
     IN(ST_STEP) | IN(ST_TERMINATED), ANY_STATE},
    {IN(ST_INSTANTIATED), IN(ST_INSTANTIATED), IN(ST_INIT), IN(ST_STEP), IN(ST_STEP), ANY_STATE, ANY_STATE,
     IN(ST_INSTANTIATED) | IN(ST_INIT) | IN(ST_STEP), IN(ST_INSTANTIATED) | IN(ST_INIT), 0, ANY_STATE}};
#undef INIT_ON

static const char *const RW_STATE_NAMES[N_ST] = {"instantiated", "in initialization mode", "stepping", "terminated",
                                                "in the error state"};

static int rw_state_ok(int state) { return state >= 0 && state < N_ST; }

static int rw_allowed(int fmi, int state, RwCall call)
{
    return rw_state_ok(state) && (fmi == 2 || fmi == 3) && (RW_ALLOWED[fmi - 2][call] & IN(state)) != 0;
}

/* the state an instance in `state` moves to when a call returns Error */
static int rw_error_state(int fmi, int state)
{
    if (fmi == 3 || state == ST_TERMINATED)
        return ST_TERMINATED;
    return ST_ERROR;
}

/* what the host does next when `call` is refused in `state` (fmiX: "fmi2" or "fmi3"), into buf */
static void rw_next_step(char *buf, size_t size, int fmi, RwCall call, int state)
{
    const char *x = fmi == 3 ? "fmi3" : "fmi2";
    const char *set_state = fmi == 3 ? "SetFMUState" : "SetFMUstate";
    if (state == ST_ERROR)
        snprintf(buf, size, "an error ended the run (see the message logged then): reset the instance (%sReset) or "
                 "restore an FMU state stored before the error (%s%s)", x, x, set_state);
    else if (state == ST_TERMINATED)
        snprintf(buf, size, "reset the instance (%sReset) to run again, or restore a stored FMU state (%s%s)%s", x, x,
                 set_state, fmi == 3 ? " (FMI 3.0 terminates an instance after any error)" : "");
    else if (call == RW_SET_PARAMETER)
        snprintf(buf, size, "fixed parameters are set before %sExitInitializationMode: reset the instance (%sReset) "
                 "and set them again", x, x);
    else if (call == RW_SETUP_EXPERIMENT || call == RW_ENTER_INIT || (call == RW_EXIT_INIT && state == ST_STEP))
        snprintf(buf, size, "the instance is initialised once per run: reset it (%sReset) to initialise it again", x);
    else if (state == ST_INSTANTIATED && call == RW_DO_STEP)
        snprintf(buf, size, "initialise it first: %sEnterInitializationMode, then %sExitInitializationMode", x, x);
    else if (state == ST_INSTANTIATED)
        snprintf(buf, size, "enter initialization mode first (%sEnterInitializationMode)", x);
    else if (state == ST_INIT)
        snprintf(buf, size, "exit initialization mode first (%sExitInitializationMode)", x);
    else
        snprintf(buf, size, "see the FMI %d.0 state machine", fmi);
}

/* the refusal message of `call` (the FMI function fn) in `state`, into buf */
static void rw_refusal(char *buf, size_t size, int fmi, RwCall call, int state, const char *fn)
{
    char states[160] = "", next[320];
    for (int s = 0; s < N_ST; s++)
        if (rw_allowed(fmi, s, call)) {
            const size_t len = strlen(states);
            snprintf(states + len, sizeof states - len, "%s%s", len ? ", " : "", RW_STATE_NAMES[s]);
        }
    rw_next_step(next, sizeof next, fmi, call, state);
    snprintf(buf, size, "%s: illegal call sequence: the instance is %s; %s is allowed when %s: %s", fn,
             rw_state_ok(state) ? RW_STATE_NAMES[state] : "in an unknown state", fn, states[0] ? states : "never",
             next);
}

/* ------------------------------------------------------------------ variables by value reference
 * The variables of both wheel FMUs (rwadist/fmu/native_build.py VARIABLES; a test compares the two), FMI 3.0 adds `time`. */
/* VR_SWITCH .. VR_SWITCH + N_SWITCH_VR - 1: the effect switches, Booleans that the effect elements own and name
   (rwadist.fmu.runtime.fmu_switches; wheel_model.h RW_SWITCH_NAMES in the native FMU) */
#define N_SWITCH_VR 2
enum { VR_SPEED = 0, VR_ACCEL = 1, VR_MODEL_FILE = 2, VR_USE_ACCEL = 3, VR_SEED = 4, VR_IMBALANCE = 5,
       VR_HARMONICS = 6, VR_MODES = 7, VR_START_STEADY = 8, VR_SWITCH = 9,
       VR_FLOOR_RES = 11, VR_MAX_ACCEL = 12, VR_MAX_STEP = 13, VR_DCM = 14, VR_POS = 23, VR_OUT = 26,
       N_VR = 38, VR_TIME = 38 };

typedef enum { RW_REAL, RW_INTEGER, RW_BOOLEAN, RW_STRING, RW_NO_TYPE } RwType;
typedef enum { RW_INPUT, RW_PARAMETER, RW_OUTPUT, RW_INDEPENDENT, RW_NO_VARIABLE } RwCausality;
static const char *const RW_TYPE_NAMES[2][4] = {{"Real", "Integer", "Boolean", "String"},
                                                {"Float64", "Int32", "Boolean", "String"}};

static const char *const RW_VAR_NAMES[N_VR + 1] = {
    "wheel_speed", "wheel_acceleration", "model_file", "use_wheel_acceleration", "seed", "imbalance", "harmonics",
    "modes", "start_steady", "effect_switch", "effect_switch", "floor_resolution", "max_acceleration",
    "max_step_size", "dcm_11", "dcm_12", "dcm_13", "dcm_21", "dcm_22", "dcm_23", "dcm_31", "dcm_32", "dcm_33", "r_x",
    "r_y", "r_z", "Fx", "Fy", "Fz", "Tx", "Ty", "Tz", "Fx_sc", "Fy_sc", "Fz_sc", "Tx_sc", "Ty_sc", "Tz_sc", "time"};

/* the type of value reference vr in FMI version fmi (RW_NO_TYPE: no variable) and its causality */
static RwType rw_variable(int fmi, unsigned vr, RwCausality *causality)
{
    RwCausality c = RW_PARAMETER;
    RwType t = RW_BOOLEAN;
    if (vr == VR_SPEED || vr == VR_ACCEL)
        c = RW_INPUT, t = RW_REAL;
    else if (vr == VR_MODEL_FILE)
        t = RW_STRING;
    else if (vr == VR_SEED)
        t = RW_INTEGER;
    else if (vr >= VR_FLOOR_RES && vr < VR_OUT)
        t = RW_REAL;
    else if (vr >= VR_OUT && vr < N_VR)
        c = RW_OUTPUT, t = RW_REAL;
    else if (vr == VR_TIME && fmi == 3)
        c = RW_INDEPENDENT, t = RW_REAL;
    else if (vr >= VR_SWITCH + N_SWITCH_VR)
        c = RW_NO_VARIABLE, t = RW_NO_TYPE;
    if (causality)
        *causality = c;
    return t;
}

/* why value reference vr cannot be set (NULL: it can, in the states RW_SET_INPUT or RW_SET_PARAMETER allow) */
static const char *rw_not_settable(int fmi, unsigned vr, RwType type)
{
    RwCausality c;
    const RwType t = rw_variable(fmi, vr, &c);
    if (t == RW_NO_TYPE || t != type)
        return t == RW_NO_TYPE ? "is no variable of this FMU" : "is a variable of another type";
    if (c == RW_OUTPUT)
        return "is an output: outputs are read, not set";
    if (c == RW_INDEPENDENT)
        return "is the independent variable time: the host advances it with fmi3DoStep";
    return NULL;
}

#endif
