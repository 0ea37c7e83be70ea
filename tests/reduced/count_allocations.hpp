// Heap allocations made so far in the reduced_test binary: its global operator new is replaced
// once, in reduced_model_test.cpp, and counts here (for the allocation-free steps).
#pragma once

extern long g_allocations;
