/*
 * bgmodelica FMU runtime: FMI 3.0 Model Exchange functions (pure ODE, no events).
 * Written for bgmodelica from the FMI 3.0 specification.
 */
#include "fmi3Functions.h"
#include "bgm_core.h"

#define INST ((bgm_inst *)instance)
#define ME_OR_ERROR(instance, fn)                                           \
    do {                                                                    \
        if (!bgm_valid(INST) || !bgm_check_kind(INST, fn, BGM_KIND_ME))     \
            return fmi3Error;                                               \
    } while (0)

fmi3Status fmi3EnterContinuousTimeMode(fmi3Instance instance) {
    ME_OR_ERROR(instance, "fmi3EnterContinuousTimeMode");
    if (!bgm_check(INST, "fmi3EnterContinuousTimeMode", BGM_MODE_EVENT)) return fmi3Error;
    INST->v.mode = BGM_MODE_CONT;
    return fmi3OK;
}

fmi3Status fmi3CompletedIntegratorStep(fmi3Instance instance,
                                       fmi3Boolean noSetFMUStatePriorToCurrentPoint,
                                       fmi3Boolean *enterEventMode,
                                       fmi3Boolean *terminateSimulation) {
    (void)noSetFMUStatePriorToCurrentPoint;
    ME_OR_ERROR(instance, "fmi3CompletedIntegratorStep");
    if (!bgm_check(INST, "fmi3CompletedIntegratorStep", BGM_MODE_CONT)) return fmi3Error;
    if (!enterEventMode || !terminateSimulation) {
        bgm_error(INST, "fmi3CompletedIntegratorStep: NULL output argument");
        return fmi3Error;
    }
    *enterEventMode = fmi3False;
    *terminateSimulation = fmi3False;
#if BGM_HYBRID
    bgm_hyb_track(INST, INST->v.time, INST->v.x);
#endif
    return fmi3OK;
}

fmi3Status fmi3SetTime(fmi3Instance instance, fmi3Float64 time) {
    ME_OR_ERROR(instance, "fmi3SetTime");
    return (fmi3Status)bgm_set_time(INST, "fmi3SetTime", time);
}

fmi3Status fmi3SetContinuousStates(fmi3Instance instance, const fmi3Float64 continuousStates[],
                                   size_t nContinuousStates) {
    ME_OR_ERROR(instance, "fmi3SetContinuousStates");
    return (fmi3Status)bgm_set_states(INST, "fmi3SetContinuousStates", continuousStates,
                                      nContinuousStates);
}

fmi3Status fmi3GetContinuousStateDerivatives(fmi3Instance instance, fmi3Float64 derivatives[],
                                             size_t nContinuousStates) {
    ME_OR_ERROR(instance, "fmi3GetContinuousStateDerivatives");
    return (fmi3Status)bgm_get_derivatives(INST, "fmi3GetContinuousStateDerivatives",
                                           derivatives, nContinuousStates);
}

fmi3Status fmi3GetEventIndicators(fmi3Instance instance, fmi3Float64 eventIndicators[],
                                  size_t nEventIndicators) {
    ME_OR_ERROR(instance, "fmi3GetEventIndicators");
#if BGM_HYBRID
    return (fmi3Status)bgm_hyb_event_indicators(INST, "fmi3GetEventIndicators", eventIndicators,
                                                nEventIndicators);
#else
    (void)eventIndicators;
    return (fmi3Status)bgm_event_indicators(INST, "fmi3GetEventIndicators", nEventIndicators);
#endif
}

fmi3Status fmi3GetContinuousStates(fmi3Instance instance, fmi3Float64 continuousStates[],
                                   size_t nContinuousStates) {
    ME_OR_ERROR(instance, "fmi3GetContinuousStates");
    return (fmi3Status)bgm_get_states(INST, "fmi3GetContinuousStates", continuousStates,
                                      nContinuousStates);
}

fmi3Status fmi3GetNominalsOfContinuousStates(fmi3Instance instance, fmi3Float64 nominals[],
                                             size_t nContinuousStates) {
    ME_OR_ERROR(instance, "fmi3GetNominalsOfContinuousStates");
    return (fmi3Status)bgm_get_nominals(INST, "fmi3GetNominalsOfContinuousStates", nominals,
                                        nContinuousStates);
}

fmi3Status fmi3GetNumberOfEventIndicators(fmi3Instance instance, size_t *nEventIndicators) {
    ME_OR_ERROR(instance, "fmi3GetNumberOfEventIndicators");
    if (!nEventIndicators) {
        bgm_error(INST, "fmi3GetNumberOfEventIndicators: NULL argument");
        return fmi3Error;
    }
#if BGM_HYBRID
    *nEventIndicators = BGM_NZ;
#else
    *nEventIndicators = 0;
#endif
    return fmi3OK;
}

fmi3Status fmi3GetNumberOfContinuousStates(fmi3Instance instance, size_t *nContinuousStates) {
    ME_OR_ERROR(instance, "fmi3GetNumberOfContinuousStates");
    if (!nContinuousStates) {
        bgm_error(INST, "fmi3GetNumberOfContinuousStates: NULL argument");
        return fmi3Error;
    }
    *nContinuousStates = BGM_NX;
    return fmi3OK;
}
