/* Types shared by the FMI 3.0 test-FMU runtime (glue3.c) and the model files. */
#ifndef GLUE3_H
#define GLUE3_H
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi3Functions.h"

enum { T_F32, T_F64, T_I8, T_U8, T_I16, T_U16, T_I32, T_U32, T_I64, T_U64, T_BOOL, T_STR,
       T_BIN };

typedef struct {
    unsigned vr;
    int type;
    size_t n;            /* number of elements (1 for scalars) */
} Var;

static const size_t TYPE_SIZE[] = {sizeof(float), sizeof(double), 1, 1, 2, 2, 4, 4, 8, 8,
                                   sizeof(fmi3Boolean), sizeof(char *), sizeof(void *)};

#endif
