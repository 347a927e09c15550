#include "report.h"

const char *plume_reason_name(plume_reason r)
{
    switch (r) {
    case PLUME_REASON_CONVERGED: return "converged";
    case PLUME_REASON_ITERATION_CAP: return "iteration cap";
    case PLUME_REASON_LINE_SEARCH: return "line-search failure";
    case PLUME_REASON_INFEASIBLE: return "infeasible";
    case PLUME_REASON_NUMERICAL: return "numerical failure";
    case PLUME_REASON_SINGLE_STEP: return "single linearised step";
    case PLUME_REASON_CONTACT_SET: return "steps blocked outside the contact set";
    case PLUME_REASON_STALLED: return "stalled";
    case PLUME_REASON_PRESCRIBED_CROSSING: return "prescribed motion runs into a body";
    }
    return "unknown";
}
