/* Part of neighbor-cosim's build of fmusim (not from the Reference-FMUs sources): fmusim links
 * SUNDIALS' CVODE for one use, integrating a model-exchange FMU with `--solver cvode`. The tests
 * run co-simulation FMUs only, and Debian's CVODE package pulls in MPI, PETSc and a Fortran
 * compiler (150 packages), so this build leaves CVODE out: asking for it is an error that says so.
 * Everything fmusim does with co-simulation FMUs is its own code, unchanged. */
#include <stdio.h>

#include "FMICVode.h"

FMISolver *FMICVodeCreate(const FMISolverParameters *solverFunctions) {
    (void)solverFunctions;
    fprintf(stderr, "fmusim: this build has no CVODE (--solver cvode); use --solver euler or a co-simulation FMU\n");
    return NULL;
}

void FMICVodeFree(FMISolver *solver) { (void)solver; }

FMISolverStatus FMICVodeStep(FMISolver *solver, double nextTime, double *timeReached, bool *stateEvent) {
    (void)solver; (void)nextTime; (void)timeReached; (void)stateEvent;
    return FMISolverError;
}

FMISolverStatus FMICVodeReset(FMISolver *solver, double time) {
    (void)solver; (void)time;
    return FMISolverError;
}
