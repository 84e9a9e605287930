// drive_test_util.h: what the tests of the drive window share: the SDL
// events of a key, a virtual game pad, and ticks of a drive session on a
// virtual clock (240 ticks per second of wall time).
#ifndef CRANESIM_DRIVE_TEST_UTIL_H
#define CRANESIM_DRIVE_TEST_UTIL_H

#include "drive_session.h"

#include <SDL2/SDL.h>
#include <string.h>

// A key pressed (down 1) or released (down 0), as the keyboard sends it.
static inline void push_key(SDL_Scancode sc, int down) {
    SDL_Event ev;
    memset(&ev, 0, sizeof ev);
    ev.type = down ? SDL_KEYDOWN : SDL_KEYUP;
    ev.key.state = down ? SDL_PRESSED : SDL_RELEASED;
    ev.key.keysym.scancode = sc;
    ev.key.keysym.sym = SDL_GetKeyFromScancode(sc);
    SDL_PushEvent(&ev);
}

// The session's ticks over `seconds` of the virtual wall clock *wall [s];
// the first nonzero result (an error, or 1 when the session ends), else 0.
static inline int run_for(drive_session* s, double* wall, double seconds) {
    int rc = 0;
    for (double end = *wall + seconds; *wall < end && rc == 0;) {
        *wall += 1.0 / 240.0;
        rc = drive_session_tick(s, *wall);
    }
    return rc;
}

// A virtual game controller with every axis and button SDL names; its
// device index, or -1 (SDL_GetError says why).
static inline int attach_pad(const char* name) {
    SDL_VirtualJoystickDesc d;
    memset(&d, 0, sizeof d);
    d.version = SDL_VIRTUAL_JOYSTICK_DESC_VERSION;
    d.type = (Uint16)SDL_JOYSTICK_TYPE_GAMECONTROLLER;
    d.naxes = SDL_CONTROLLER_AXIS_MAX;
    d.nbuttons = SDL_CONTROLLER_BUTTON_MAX;
    d.name = name;
    return SDL_JoystickAttachVirtualEx(&d);
}

#endif
