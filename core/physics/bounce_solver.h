// Internal to core/physics (rigid_world.cpp): Bullet's sequential-impulse solver with one change,
// a bounce found a hair before touching leaves at the restitution's speed.
#pragma once

#include <btBulletDynamicsCommon.h>

namespace arpipe {

// Bullet aims a contact still `gap` apart at a separating velocity of e u - gap / dt, so that the
// body ends the substep where a bounce at the surface would have put it; but it keeps that slower
// velocity, and the bounce comes out low (by 6 % in one drop of 60). Here a bouncing contact with a
// gap aims at e u: the body bounces from at most the contact processing threshold (0.1 mm) above
// the surface, at the right speed. Resting and inelastic contacts are left as Bullet sets them.
class BounceSolver : public btSequentialImpulseConstraintSolver {
 protected:
  void convertContacts(btPersistentManifold** manifolds, int count, const btContactSolverInfo& info) override;
};

}  // namespace arpipe
