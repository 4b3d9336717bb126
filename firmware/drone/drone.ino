// Drone firmware: Raspberry Pi frames in on Serial, RC pulses, pan/tilt servo
// pulses and the laser out. Everything lives in drone_app.cpp and beside it.
#include "drone_app.h"

void setup() { drone_app::setup(); }

void loop() { drone_app::loop(); }
