#include <petscsnes.h>
