/*
 * bgmodelica FMU runtime: FMI 2.0 Co-Simulation functions.  DoStep integrates with the
 * embedded BDF solver (bgm_solver.c); it is synchronous (never returns fmi2Pending) and
 * inputs are held constant over a communication step.
 * Written for bgmodelica from the FMI 2.0.x specification.
 */
#include "fmi2Functions.h"
#include "bgm_core.h"

#define INST ((bgm_inst *)c)
#define CS_OR_ERROR(c, fn)                                                  \
    do {                                                                    \
        if (!bgm_valid(INST) || !bgm_check_kind(INST, fn, BGM_KIND_CS))     \
            return fmi2Error;                                               \
    } while (0)

fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[],
                                       size_t nvr, const fmi2Integer order[],
                                       const fmi2Real value[]) {
    (void)order;
    (void)value;
    CS_OR_ERROR(c, "fmi2SetRealInputDerivatives");
    if (nvr == 0) return fmi2OK;
    bgm_error(INST, "fmi2SetRealInputDerivatives: not supported (canInterpolateInputs=false), "
              "value reference %u", vr ? vr[0] : 0u);
    return fmi2Error;
}

fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[],
                                        size_t nvr, const fmi2Integer order[],
                                        fmi2Real value[]) {
    (void)order;
    (void)value;
    CS_OR_ERROR(c, "fmi2GetRealOutputDerivatives");
    if (nvr == 0) return fmi2OK;
    bgm_error(INST, "fmi2GetRealOutputDerivatives: not supported (maxOutputDerivativeOrder=0), "
              "value reference %u", vr ? vr[0] : 0u);
    return fmi2Error;
}

fmi2Status fmi2DoStep(fmi2Component c, fmi2Real currentCommunicationPoint,
                      fmi2Real communicationStepSize,
                      fmi2Boolean noSetFMUStatePriorToCurrentCommunicationPoint) {
    (void)noSetFMUStatePriorToCurrentCommunicationPoint;
    CS_OR_ERROR(c, "fmi2DoStep");
    return (fmi2Status)bgm_do_step(INST, "fmi2DoStep", currentCommunicationPoint,
                                   communicationStepSize);
}

fmi2Status fmi2CancelStep(fmi2Component c) {
    CS_OR_ERROR(c, "fmi2CancelStep");
    bgm_error(INST, "fmi2CancelStep: DoStep is synchronous, there is nothing to cancel");
    return fmi2Error;
}

fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind s, fmi2Status *value) {
    CS_OR_ERROR(c, "fmi2GetStatus");
    if (s == fmi2DoStepStatus && value) {
        *value = fmi2OK;
        return fmi2OK;
    }
    bgm_log(INST, BGM_DISCARD, "logStatusWarning", "fmi2GetStatus: status kind %d not available",
            (int)s);
    return fmi2Discard;
}

fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind s, fmi2Real *value) {
    CS_OR_ERROR(c, "fmi2GetRealStatus");
    if (s == fmi2LastSuccessfulTime && value) {
        *value = INST->v.time;
        return fmi2OK;
    }
    bgm_log(INST, BGM_DISCARD, "logStatusWarning",
            "fmi2GetRealStatus: status kind %d not available", (int)s);
    return fmi2Discard;
}

fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind s, fmi2Integer *value) {
    (void)value;
    CS_OR_ERROR(c, "fmi2GetIntegerStatus");
    bgm_log(INST, BGM_DISCARD, "logStatusWarning",
            "fmi2GetIntegerStatus: status kind %d not available", (int)s);
    return fmi2Discard;
}

fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind s, fmi2Boolean *value) {
    CS_OR_ERROR(c, "fmi2GetBooleanStatus");
    if (s == fmi2Terminated && value) {
        *value = fmi2False;
        return fmi2OK;
    }
    bgm_log(INST, BGM_DISCARD, "logStatusWarning",
            "fmi2GetBooleanStatus: status kind %d not available", (int)s);
    return fmi2Discard;
}

fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind s, fmi2String *value) {
    (void)value;
    CS_OR_ERROR(c, "fmi2GetStringStatus");
    bgm_log(INST, BGM_DISCARD, "logStatusWarning",
            "fmi2GetStringStatus: status kind %d not available", (int)s);
    return fmi2Discard;
}
