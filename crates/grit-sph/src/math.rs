//! The one place that fixes the dimension: grit-sph is 2D (plane strain), so vectors and
//! tensors are 2-component; moving to 3D is a change of these aliases and of `DIM`.

/// Number of spatial dimensions.
pub const DIM: usize = 2;

/// A position, velocity or force vector.
pub type Vector = nalgebra::Vector2<f64>;

/// A second-order tensor (velocity gradient, in-plane stress, correction matrix L of eq. 8).
pub type Matrix = nalgebra::Matrix2<f64>;

/// The in-plane vector rotated by +90°, the 2D tangent of a contact normal.
#[inline]
pub fn perp(v: Vector) -> Vector {
    Vector::new(-v.y, v.x)
}

/// The scalar (z) cross product a × b in 2D, used for torques (eq. 17).
#[inline]
pub fn cross(a: Vector, b: Vector) -> f64 {
    a.x * b.y - a.y * b.x
}

/// ω × r for an angular velocity ω about z.
#[inline]
pub fn omega_cross(omega: f64, r: Vector) -> Vector {
    Vector::new(-omega * r.y, omega * r.x)
}

/// Rotates `v` by the angle `theta` (radians) counter-clockwise.
#[inline]
pub fn rotate(v: Vector, theta: f64) -> Vector {
    let (s, c) = sin_cos(theta);
    Vector::new(c * v.x - s * v.y, s * v.x + c * v.y)
}

/// Outer product a ⊗ b.
#[inline]
pub fn outer(a: Vector, b: Vector) -> Matrix {
    Matrix::new(a.x * b.x, a.x * b.y, a.y * b.x, a.y * b.y)
}

// The transcendental functions every result goes through, from one software implementation
// (the `libm` crate): the system's libm picks its own by CPU at load time, and a worker with
// another CPU would then compute other bits (docs/design.md, "Rules the engine keeps").

/// x^y.
#[inline]
pub fn pow(x: f64, y: f64) -> f64 {
    libm::pow(x, y)
}

/// e^x.
#[inline]
pub fn exp(x: f64) -> f64 {
    libm::exp(x)
}

/// The natural logarithm of x.
#[inline]
pub fn ln(x: f64) -> f64 {
    libm::log(x)
}

/// (sin θ, cos θ).
#[inline]
pub fn sin_cos(theta: f64) -> (f64, f64) {
    libm::sincos(theta)
}

/// tan θ.
#[inline]
pub fn tan(theta: f64) -> f64 {
    libm::tan(theta)
}
