/*
 * bgmodelica FMU runtime: FMI 2.0 Model Exchange functions.
 * The exported models are pure ODEs without events: zero event indicators, event iteration
 * converges at once, no time events.
 * Written for bgmodelica from the FMI 2.0.x specification.
 */
#include "fmi2Functions.h"
#include "bgm_core.h"

#define INST ((bgm_inst *)c)
#define ME_OR_ERROR(c, fn)                                                  \
    do {                                                                    \
        if (!bgm_valid(INST) || !bgm_check_kind(INST, fn, BGM_KIND_ME))     \
            return fmi2Error;                                               \
    } while (0)

fmi2Status fmi2EnterEventMode(fmi2Component c) {
    ME_OR_ERROR(c, "fmi2EnterEventMode");
    if (!bgm_check(INST, "fmi2EnterEventMode", BGM_MODE_EVENT | BGM_MODE_CONT)) return fmi2Error;
    INST->v.mode = BGM_MODE_EVENT;
#if BGM_HYBRID
    return (fmi2Status)bgm_hyb_enter_event(INST, "fmi2EnterEventMode");
#else
    return fmi2OK;
#endif
}

fmi2Status fmi2NewDiscreteStates(fmi2Component c, fmi2EventInfo *eventInfo) {
    ME_OR_ERROR(c, "fmi2NewDiscreteStates");
    if (!bgm_check(INST, "fmi2NewDiscreteStates", BGM_MODE_EVENT)) return fmi2Error;
    if (!eventInfo) {
        bgm_error(INST, "fmi2NewDiscreteStates: eventInfo is NULL");
        return fmi2Error;
    }
#if BGM_HYBRID
    {
        int need, changed, defined;
        double next;
        if (bgm_hyb_update(INST, "fmi2NewDiscreteStates", &need, &changed, &defined, &next) !=
            BGM_OK)
            return fmi2Error;
        eventInfo->newDiscreteStatesNeeded = need ? fmi2True : fmi2False;
        eventInfo->terminateSimulation = fmi2False;
        eventInfo->nominalsOfContinuousStatesChanged = fmi2False;
        eventInfo->valuesOfContinuousStatesChanged = changed ? fmi2True : fmi2False;
        eventInfo->nextEventTimeDefined = defined ? fmi2True : fmi2False;
        eventInfo->nextEventTime = next;
        return fmi2OK;
    }
#endif
    eventInfo->newDiscreteStatesNeeded = fmi2False;
    eventInfo->terminateSimulation = fmi2False;
    eventInfo->nominalsOfContinuousStatesChanged = fmi2False;
    eventInfo->valuesOfContinuousStatesChanged = fmi2False;
    eventInfo->nextEventTimeDefined = fmi2False;
    eventInfo->nextEventTime = 0.0;
    return fmi2OK;
}

fmi2Status fmi2EnterContinuousTimeMode(fmi2Component c) {
    ME_OR_ERROR(c, "fmi2EnterContinuousTimeMode");
    if (!bgm_check(INST, "fmi2EnterContinuousTimeMode", BGM_MODE_EVENT)) return fmi2Error;
    INST->v.mode = BGM_MODE_CONT;
    return fmi2OK;
}

fmi2Status fmi2CompletedIntegratorStep(fmi2Component c,
                                       fmi2Boolean noSetFMUStatePriorToCurrentPoint,
                                       fmi2Boolean *enterEventMode,
                                       fmi2Boolean *terminateSimulation) {
    (void)noSetFMUStatePriorToCurrentPoint;
    ME_OR_ERROR(c, "fmi2CompletedIntegratorStep");
    if (!bgm_check(INST, "fmi2CompletedIntegratorStep", BGM_MODE_CONT)) return fmi2Error;
    if (!enterEventMode || !terminateSimulation) {
        bgm_error(INST, "fmi2CompletedIntegratorStep: NULL output argument");
        return fmi2Error;
    }
    *enterEventMode = fmi2False;
    *terminateSimulation = fmi2False;
#if BGM_HYBRID
    bgm_hyb_track(INST, INST->v.time, INST->v.x);
#endif
    return fmi2OK;
}

fmi2Status fmi2SetTime(fmi2Component c, fmi2Real time) {
    ME_OR_ERROR(c, "fmi2SetTime");
    return (fmi2Status)bgm_set_time(INST, "fmi2SetTime", time);
}

fmi2Status fmi2SetContinuousStates(fmi2Component c, const fmi2Real x[], size_t nx) {
    ME_OR_ERROR(c, "fmi2SetContinuousStates");
    return (fmi2Status)bgm_set_states(INST, "fmi2SetContinuousStates", x, nx);
}

fmi2Status fmi2GetDerivatives(fmi2Component c, fmi2Real derivatives[], size_t nx) {
    ME_OR_ERROR(c, "fmi2GetDerivatives");
    return (fmi2Status)bgm_get_derivatives(INST, "fmi2GetDerivatives", derivatives, nx);
}

fmi2Status fmi2GetEventIndicators(fmi2Component c, fmi2Real eventIndicators[], size_t ni) {
    ME_OR_ERROR(c, "fmi2GetEventIndicators");
#if BGM_HYBRID
    return (fmi2Status)bgm_hyb_event_indicators(INST, "fmi2GetEventIndicators", eventIndicators,
                                                ni);
#else
    (void)eventIndicators;
    return (fmi2Status)bgm_event_indicators(INST, "fmi2GetEventIndicators", ni);
#endif
}

fmi2Status fmi2GetContinuousStates(fmi2Component c, fmi2Real x[], size_t nx) {
    ME_OR_ERROR(c, "fmi2GetContinuousStates");
    return (fmi2Status)bgm_get_states(INST, "fmi2GetContinuousStates", x, nx);
}

fmi2Status fmi2GetNominalsOfContinuousStates(fmi2Component c, fmi2Real x_nominal[],
                                             size_t nx) {
    ME_OR_ERROR(c, "fmi2GetNominalsOfContinuousStates");
    return (fmi2Status)bgm_get_nominals(INST, "fmi2GetNominalsOfContinuousStates", x_nominal,
                                        nx);
}
