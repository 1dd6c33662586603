/* SPDX-License-Identifier: Apache-2.0 */
/* io's own faults: the wrong_output faults of its --fault arguments (fi/wrong_output.h) acting
 * on this replica's actuator command before it goes on CAN, and the lines that report them. */
#include <string.h>

#include "io_core.h"

void io_faults_init(io_fault_state_t *st)
{
    for (unsigned k = 0; k < IO_MAX_FAULTS; k++)
        fi_wo_reset(&st->wo[k]);
}

void io_cmd_faults(const io_settings_t *s, io_fault_state_t *st, int64_t t_ns,
                   rpas_act_cmd_msg_t *cmd, io_fault_reports_t *out)
{
    out->n = 0;
    for (unsigned k = 0; k < s->n_faults; k++) {
        const fi_wo_t *f = &s->fault[k];
        double *axis[IO_AXES] = {NULL, NULL, NULL, NULL};
        if (cmd) {
            axis[0] = &cmd->elev;
            axis[1] = &cmd->ail;
            axis[2] = &cmd->rud;
            axis[3] = &cmd->thr;
        }
        fi_wo_reports_t rep;
        fi_wo_apply(f, &st->wo[k], t_ns, axis[f->axis], &rep);
        for (int i = 0; i < rep.n && out->n < 2 * IO_MAX_FAULTS; i++)
            memcpy(out->line[out->n++], rep.line[i], FI_WO_REPORT_MAX);
    }
}
