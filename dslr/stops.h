// The steps a camera's dials take: third-stop f-numbers, shutter times and ISO speeds. The
// advice rounds its suggestions to them and the studio's sliders step through them.
#pragma once

namespace rigc::dslr {

// Third-stop f-numbers, over the language's apertures.
inline constexpr double kFNumberStops[] = {1.2, 1.4, 1.6, 1.8, 2,  2.2, 2.5, 2.8, 3.2, 3.5, 4,  4.5,
                                           5,   5.6, 6.3, 7.1, 8,  9,   10,  11,  13,  14,  16, 18,
                                           20,  22,  25,  29,  32, 36,  40,  45,  51,  57,  64};

// Third-stop shutter times in seconds, 30 s to 1/8000 s.
inline constexpr double kShutterStops[] = {
    30,         25,         20,         15,         13,         10,         8,          6,
    5,          4,          3.2,        2.5,        2,          1.6,        1.3,        1,
    0.8,        0.6,        0.5,        0.4,        0.3,        1.0 / 4,    1.0 / 5,    1.0 / 6,
    1.0 / 8,    1.0 / 10,   1.0 / 13,   1.0 / 15,   1.0 / 20,   1.0 / 25,   1.0 / 30,   1.0 / 40,
    1.0 / 50,   1.0 / 60,   1.0 / 80,   1.0 / 100,  1.0 / 125,  1.0 / 160,  1.0 / 200,  1.0 / 250,
    1.0 / 320,  1.0 / 400,  1.0 / 500,  1.0 / 640,  1.0 / 800,  1.0 / 1000, 1.0 / 1250, 1.0 / 1600,
    1.0 / 2000, 1.0 / 2500, 1.0 / 3200, 1.0 / 4000, 1.0 / 5000, 1.0 / 6400, 1.0 / 8000};

// Third-stop ISO speeds, then the whole stops above 6400 that bodies offer.
inline constexpr double kIsoStops[] = {50,   64,   80,   100,  125,  160,  200,   250,
                                       320,  400,  500,  640,  800,  1000, 1250,  1600,
                                       2000, 2500, 3200, 4000, 5000, 6400, 12800, 25600};

}  // namespace rigc::dslr
