// Loop accounting for the specular pass (capabilities::loop_budget). Every
// loop iteration of the pass, including those of the functions it shares
// with other passes, first calls loop_iteration(), which returns false once
// this invocation has run its budget: the loops then end, and the pixel is
// reported over budget (SpecularPass splits the photon gathers into more
// dispatches and runs again). A driver's own cap, such as llvmpipe's 65,535
// iterations, is therefore never reached, and nothing is cut silently.

var<private> iterations_spent: u32 = 0u;
var<private> over_budget: bool = false;

fn loop_iteration() -> bool {
    iterations_spent += 1u;
    if (iterations_spent > slice.iteration_budget) {
        over_budget = true;
    }
    return !over_budget;
}
