/*
 * bgmodelica FMU runtime: FMI 3.0 Co-Simulation functions.  DoStep integrates with the
 * embedded BDF solver (bgm_solver.c); no early return, no intermediate update; Event Mode
 * is supported trivially (the model has no events) when instantiated with eventModeUsed.
 * Written for bgmodelica from the FMI 3.0 specification.
 */
#include "fmi3Functions.h"
#include "bgm_core.h"

#define INST ((bgm_inst *)instance)
#define CS_OR_ERROR(instance, fn)                                           \
    do {                                                                    \
        if (!bgm_valid(INST) || !bgm_check_kind(INST, fn, BGM_KIND_CS))     \
            return fmi3Error;                                               \
    } while (0)

fmi3Status fmi3EnterStepMode(fmi3Instance instance) {
    CS_OR_ERROR(instance, "fmi3EnterStepMode");
    if (!bgm_check(INST, "fmi3EnterStepMode", BGM_MODE_EVENT)) return fmi3Error;
    INST->v.mode = BGM_MODE_STEP;
    return fmi3OK;
}

fmi3Status fmi3GetOutputDerivatives(fmi3Instance instance,
                                    const fmi3ValueReference valueReferences[],
                                    size_t nValueReferences, const fmi3Int32 orders[],
                                    fmi3Float64 values[], size_t nValues) {
    (void)orders;
    (void)values;
    (void)nValues;
    CS_OR_ERROR(instance, "fmi3GetOutputDerivatives");
    if (nValueReferences == 0) return fmi3OK;
    bgm_error(INST, "fmi3GetOutputDerivatives: not supported (maxOutputDerivativeOrder=0), "
              "value reference %u", valueReferences ? valueReferences[0] : 0u);
    return fmi3Error;
}

fmi3Status fmi3DoStep(fmi3Instance instance, fmi3Float64 currentCommunicationPoint,
                      fmi3Float64 communicationStepSize,
                      fmi3Boolean noSetFMUStatePriorToCurrentPoint,
                      fmi3Boolean *eventHandlingNeeded, fmi3Boolean *terminateSimulation,
                      fmi3Boolean *earlyReturn, fmi3Float64 *lastSuccessfulTime) {
    bgm_status s;
    (void)noSetFMUStatePriorToCurrentPoint;
    CS_OR_ERROR(instance, "fmi3DoStep");
    s = bgm_do_step(INST, "fmi3DoStep", currentCommunicationPoint, communicationStepSize);
    if (eventHandlingNeeded) *eventHandlingNeeded = fmi3False;
    if (terminateSimulation) *terminateSimulation = fmi3False;
    if (earlyReturn) *earlyReturn = fmi3False;
#if BGM_HYBRID
    if (s == BGM_OK && eventHandlingNeeded && INST->hw.event_needed)
        *eventHandlingNeeded = fmi3True;
    if (s == BGM_OK && earlyReturn &&
        INST->v.time < currentCommunicationPoint + communicationStepSize)
        *earlyReturn = fmi3True;
#endif
    if (lastSuccessfulTime) *lastSuccessfulTime = INST->v.time;
    return (fmi3Status)s;
}
