// Glue between the Arduino API (real or fake) and the logic: the sketch's
// setup() and loop() bodies.
#ifndef DRONE_APP_H
#define DRONE_APP_H

#include "drone_logic.h"

namespace drone_app {

void setup();
void loop();
const drone::Drone& logic();  // for the host build's reporting

}  // namespace drone_app

#endif
