// Build options of the drone sketch. In the Arduino IDE, choose them here: a #define in drone.ino would not
// reach the sketch's .cpp files, and IDE 1.8 has no per-sketch compiler flags. `make firmware` passes the
// same names as -D flags instead (firmware.mk builds uno_ppm with -DDRONE_PPM).
#ifndef DRONE_CONFIG_H
#define DRONE_CONFIG_H

// PPM-sum output, for flight controllers with one PPM input (Pixhawk, Cube and most boards since): uncomment
// to send the five RC channels as one PPM train on the spec's PPM pin. Leave it commented for parallel PWM,
// one wire per channel (APM 2.x).
// #define DRONE_PPM

#endif
