/* Prints the core's model table, one name a line: the list every program's --help, man
 * page and message comment must name in full where it lists models (check_man.py). */
#include <stdio.h>
#include "lagsim/lagsim.h"

int main(void)
{
    for (int k = 0; k < LAG_MODEL_COUNT; k++) puts(lag_model_info_get((lag_model_kind)k)->name);
    return 0;
}
