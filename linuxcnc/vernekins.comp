component vernekins "VERNE 5-axis kinematics (verne's analytic solvers, crates/verne-kins)";

description
"""
Kinematics module (LinuxCNC 2.9 uspace, userkins style, KINEMATICS_BOTH) of the VERNE machine.
World: X Y Z = tool tip in the workpiece frame (mm); A = phi1, C = phi2, the tool orientation
angles of AIM 2007 eq. (8) (degrees). Joints: 0..2 = sliders rho1..rho3 (mm), 3 = theta1
(tilting axis, degrees), 4 = theta2 (rotary axis, degrees).

The inverse keeps the branch of the incoming joints (proved from them alone where it can be,
by the complete solve otherwise) and unwraps theta2 next to them; the forward follows the
previous assembly mode (certified tracking, the complete solution when
tracking cannot prove its step). A pose that cannot be reached on the same branch, inside the
limits and away from singularities makes the call fail: motion stops with a kinematics error,
never a jump. See docs/linuxcnc.md.

Module parameter: machine=PATH, a verne machine file (TOML or key,value CSV); the embedded
VERNE machine when empty.
""";
// halcompile needs a function or a pin to make an instance; motion does not use this one.
pin out s32 dummy = 0 "unused";
function _ nofp;
option singleton yes;
option extra_setup yes;
license "GPL";
author "verne project";
;;

#include "rtapi_math.h"
#include "rtapi_string.h"
#include "kinematics.h"
#include "verne_kins.h"

static char *machine = "";
RTAPI_MP_STRING(machine, "verne machine file (default: the embedded VERNE machine)");

static struct vk_haldata {
    hal_u32_t   *fail_count;
    hal_s32_t   *last_status;
    hal_u32_t   *inverse_calls;
    hal_u32_t   *forward_calls;
    hal_u32_t   *ik_branches;
    hal_u32_t   *ik_fallbacks;
    hal_u32_t   *fk_modes;
    hal_float_t *tool_length;
} *vk;

static VerneKins *kins;

FUNCTION(_) { dummy = 0; }

EXTRA_SETUP() {
    char err[512];
    int res = 0;
    vk = hal_malloc(sizeof(*vk));
    if (!vk) return -1;
    res += hal_pin_u32_newf(HAL_OUT, &vk->fail_count, comp_id, "vernekins.fail-count");
    res += hal_pin_s32_newf(HAL_OUT, &vk->last_status, comp_id, "vernekins.last-status");
    res += hal_pin_u32_newf(HAL_OUT, &vk->inverse_calls, comp_id, "vernekins.inverse-calls");
    res += hal_pin_u32_newf(HAL_OUT, &vk->forward_calls, comp_id, "vernekins.forward-calls");
    res += hal_pin_u32_newf(HAL_OUT, &vk->ik_branches, comp_id, "vernekins.ik-branches");
    res += hal_pin_u32_newf(HAL_OUT, &vk->ik_fallbacks, comp_id, "vernekins.ik-fallbacks");
    res += hal_pin_u32_newf(HAL_OUT, &vk->fk_modes, comp_id, "vernekins.fk-modes");
    res += hal_pin_float_newf(HAL_IN, &vk->tool_length, comp_id, "vernekins.tool-length");
    if (res) return -1;
    *vk->fail_count = 0; *vk->last_status = 0;
    *vk->inverse_calls = 0; *vk->forward_calls = 0;
    *vk->ik_branches = 0; *vk->ik_fallbacks = 0; *vk->fk_modes = 0;
    /* Start-up, not the servo thread: reading the machine file and allocating are fine. */
    err[0] = 0;
    kins = verne_kins_new(machine, err, sizeof(err));
    if (!kins) {
        rtapi_print_msg(RTAPI_MSG_ERR, "vernekins: machine '%s': %s\n", machine, err);
        return -1;
    }
    *vk->tool_length = verne_kins_tool_length(kins);
    rtapi_print_msg(RTAPI_MSG_INFO, "vernekins: machine '%s', tool length %f mm\n",
                    machine, *vk->tool_length);
    return 0;
}

/* The tool length pin applies from the next call. */
static inline int vk_tool(void) {
    return verne_kins_set_tool_length(kins, *vk->tool_length) == VERNE_KINS_STATUS_OK ? 0 : -1;
}

static inline int vk_record(VerneKinsStatus r) {
    if (r != VERNE_KINS_STATUS_OK) {
        (*vk->fail_count)++;
        *vk->last_status = (int)r;
        return -1;
    }
    return 0;
}

int kinematicsForward(const double *j, EmcPose *pos,
                      const KINEMATICS_FORWARD_FLAGS *fflags,
                      KINEMATICS_INVERSE_FLAGS *iflags)
{
    double w[5] = { pos->tran.x, pos->tran.y, pos->tran.z, pos->a, pos->c };
    VerneKinsInfo info = { 0, 0 };
    (*vk->forward_calls)++;
    if (vk_tool()) return vk_record(VERNE_KINS_STATUS_BAD_ARGUMENTS);
    if (vk_record(verne_kins_forward(kins, j, w, 0u, &info))) return -1;
    *vk->fk_modes = info.modes;
    pos->tran.x = w[0]; pos->tran.y = w[1]; pos->tran.z = w[2];
    pos->a = w[3]; pos->b = 0; pos->c = w[4];
    pos->u = pos->v = pos->w = 0;
    return 0;
}

int kinematicsInverse(const EmcPose *pos, double *j,
                      const KINEMATICS_INVERSE_FLAGS *iflags,
                      KINEMATICS_FORWARD_FLAGS *fflags)
{
    const double w[5] = { pos->tran.x, pos->tran.y, pos->tran.z, pos->a, pos->c };
    double jj[5] = { j[0], j[1], j[2], j[3], j[4] };   /* the previous joints: the branch */
    VerneKinsInfo info = { 0, 0 };
    int n;
    VerneKinsStatus r;
    (*vk->inverse_calls)++;
    if (vk_tool()) return vk_record(VERNE_KINS_STATUS_BAD_ARGUMENTS);
    r = verne_kins_inverse(kins, w, jj, 0u, &info);
    *vk->ik_fallbacks = (hal_u32_t)verne_kins_inverse_fallbacks(kins);
    if (vk_record(r)) return -1;
    *vk->ik_branches = info.branches;
    for (n = 0; n < 5; n++) j[n] = jj[n];
    return 0;
}

int kinematicsHome(EmcPose *world, double *joint,
                   KINEMATICS_FORWARD_FLAGS *fflags,
                   KINEMATICS_INVERSE_FLAGS *iflags)
{
    *fflags = 0; *iflags = 0;
    return kinematicsForward(joint, world, fflags, iflags);
}

KINEMATICS_TYPE kinematicsType(void) { return KINEMATICS_BOTH; }

KINS_NOT_SWITCHABLE
EXPORT_SYMBOL(kinematicsType);
EXPORT_SYMBOL(kinematicsForward);
EXPORT_SYMBOL(kinematicsInverse);
EXPORT_SYMBOL(kinematicsHome);
