//! The vector type the geometry is written against. Shapes and mass properties are generic over
//! [`Vector`] so 3D spheres and sphere clumps (Leonardi et al. 2014, Sect. 3, composite elements)
//! only need a `Vec3` implementation; the 2D engine uses [`Vec2`].

use serde::{Deserialize, Serialize};
use std::ops::{Add, AddAssign, Mul, Neg, Sub, SubAssign};

/// What the geometry needs from a vector: linear algebra plus the dimension.
pub trait Vector:
    Copy
    + Default
    + Send
    + Sync
    + PartialEq
    + std::fmt::Debug
    + Add<Output = Self>
    + Sub<Output = Self>
    + Neg<Output = Self>
    + Mul<f64, Output = Self>
    + AddAssign
    + SubAssign
{
    /// Spatial dimension (2 or 3).
    const DIM: usize;
    /// Angular quantities (angular velocity, torque): a scalar in 2D, a vector in 3D.
    type Angular: Copy + Default + Send + Sync + std::fmt::Debug;
    fn dot(self, o: Self) -> f64;
    fn component(self, k: usize) -> f64;
    fn norm2(self) -> f64 {
        self.dot(self)
    }
    fn norm(self) -> f64 {
        self.norm2().sqrt()
    }
}

/// A 2D vector of f64 (`repr(C)`: x then y; the pair kernel loads them as a line).
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize, bytemuck::Pod, bytemuck::Zeroable,
)]
#[repr(C)]
pub struct Vec2 {
    pub x: f64,
    pub y: f64,
}

impl Vec2 {
    pub const ZERO: Vec2 = Vec2 { x: 0.0, y: 0.0 };
    #[inline]
    pub const fn new(x: f64, y: f64) -> Self {
        Self { x, y }
    }
    /// z-component of the cross product `self × o`.
    #[inline]
    pub fn cross(self, o: Vec2) -> f64 {
        self.x * o.y - self.y * o.x
    }
    /// `ω ẑ × self`: the velocity of a point at `self` on a body spinning at `w`.
    #[inline]
    pub fn spin(self, w: f64) -> Vec2 {
        Vec2::new(-w * self.y, w * self.x)
    }
    /// Rotated counter-clockwise by `angle` (radians).
    #[inline]
    pub fn rotated(self, angle: f64) -> Vec2 {
        let (s, c) = angle.sin_cos();
        self.rotated_sc(s, c)
    }
    /// Rotated by the angle whose sine and cosine are `s` and `c` (the bits of
    /// [`Vec2::rotated`] for `angle.sin_cos()`; one `sin_cos` for every circle of a body).
    #[inline]
    pub fn rotated_sc(self, s: f64, c: f64) -> Vec2 {
        Vec2::new(c * self.x - s * self.y, s * self.x + c * self.y)
    }
    /// Perpendicular (rotated +90°).
    #[inline]
    pub fn perp(self) -> Vec2 {
        Vec2::new(-self.y, self.x)
    }
}

impl Vector for Vec2 {
    const DIM: usize = 2;
    type Angular = f64;
    #[inline]
    fn dot(self, o: Self) -> f64 {
        self.x * o.x + self.y * o.y
    }
    fn component(self, k: usize) -> f64 {
        if k == 0 { self.x } else { self.y }
    }
}

impl Add for Vec2 {
    type Output = Vec2;
    #[inline]
    fn add(self, o: Vec2) -> Vec2 {
        Vec2::new(self.x + o.x, self.y + o.y)
    }
}
impl Sub for Vec2 {
    type Output = Vec2;
    #[inline]
    fn sub(self, o: Vec2) -> Vec2 {
        Vec2::new(self.x - o.x, self.y - o.y)
    }
}
impl Neg for Vec2 {
    type Output = Vec2;
    #[inline]
    fn neg(self) -> Vec2 {
        Vec2::new(-self.x, -self.y)
    }
}
impl Mul<f64> for Vec2 {
    type Output = Vec2;
    #[inline]
    fn mul(self, s: f64) -> Vec2 {
        Vec2::new(self.x * s, self.y * s)
    }
}
impl AddAssign for Vec2 {
    #[inline]
    fn add_assign(&mut self, o: Vec2) {
        self.x += o.x;
        self.y += o.y;
    }
}
impl SubAssign for Vec2 {
    #[inline]
    fn sub_assign(&mut self, o: Vec2) {
        self.x -= o.x;
        self.y -= o.y;
    }
}

/// A 3D vector of f64 (`repr(C)`: x, y, z), the state vector of the sphere engine
/// ([`crate::spheres`]); angular quantities are vectors too.
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize, bytemuck::Pod, bytemuck::Zeroable,
)]
#[repr(C)]
pub struct Vec3 {
    pub x: f64,
    pub y: f64,
    pub z: f64,
}

impl Vec3 {
    pub const ZERO: Vec3 = Vec3 {
        x: 0.0,
        y: 0.0,
        z: 0.0,
    };
    #[inline]
    pub const fn new(x: f64, y: f64, z: f64) -> Self {
        Self { x, y, z }
    }
    /// The cross product `self × o`.
    #[inline]
    pub fn cross(self, o: Vec3) -> Vec3 {
        Vec3::new(
            self.y * o.z - self.z * o.y,
            self.z * o.x - self.x * o.z,
            self.x * o.y - self.y * o.x,
        )
    }
    /// Component `k` (0, 1, 2) mutable.
    #[inline]
    pub fn component_mut(&mut self, k: usize) -> &mut f64 {
        match k {
            0 => &mut self.x,
            1 => &mut self.y,
            _ => &mut self.z,
        }
    }
    /// True if every component is finite.
    #[inline]
    pub fn is_finite(self) -> bool {
        self.x.is_finite() && self.y.is_finite() && self.z.is_finite()
    }
}

/// To nalgebra, where the rotations (quaternions, eigen-decompositions) are.
impl From<Vec3> for nalgebra::Vector3<f64> {
    #[inline]
    fn from(v: Vec3) -> Self {
        nalgebra::Vector3::new(v.x, v.y, v.z)
    }
}

impl From<nalgebra::Vector3<f64>> for Vec3 {
    #[inline]
    fn from(v: nalgebra::Vector3<f64>) -> Self {
        Vec3::new(v.x, v.y, v.z)
    }
}

impl Vec3 {
    /// `self` turned by the rotation `q`.
    #[inline]
    pub fn rotated_by(self, q: &nalgebra::UnitQuaternion<f64>) -> Vec3 {
        q.transform_vector(&self.into()).into()
    }
    /// `self` turned by the inverse of `q`.
    #[inline]
    pub fn rotated_back_by(self, q: &nalgebra::UnitQuaternion<f64>) -> Vec3 {
        q.inverse_transform_vector(&self.into()).into()
    }
}

impl Vector for Vec3 {
    const DIM: usize = 3;
    type Angular = Vec3;
    #[inline]
    fn dot(self, o: Self) -> f64 {
        self.x * o.x + self.y * o.y + self.z * o.z
    }
    fn component(self, k: usize) -> f64 {
        match k {
            0 => self.x,
            1 => self.y,
            _ => self.z,
        }
    }
}

impl Add for Vec3 {
    type Output = Vec3;
    #[inline]
    fn add(self, o: Vec3) -> Vec3 {
        Vec3::new(self.x + o.x, self.y + o.y, self.z + o.z)
    }
}
impl Sub for Vec3 {
    type Output = Vec3;
    #[inline]
    fn sub(self, o: Vec3) -> Vec3 {
        Vec3::new(self.x - o.x, self.y - o.y, self.z - o.z)
    }
}
impl Neg for Vec3 {
    type Output = Vec3;
    #[inline]
    fn neg(self) -> Vec3 {
        Vec3::new(-self.x, -self.y, -self.z)
    }
}
impl Mul<f64> for Vec3 {
    type Output = Vec3;
    #[inline]
    fn mul(self, s: f64) -> Vec3 {
        Vec3::new(self.x * s, self.y * s, self.z * s)
    }
}
impl AddAssign for Vec3 {
    #[inline]
    fn add_assign(&mut self, o: Vec3) {
        self.x += o.x;
        self.y += o.y;
        self.z += o.z;
    }
}
impl SubAssign for Vec3 {
    #[inline]
    fn sub_assign(&mut self, o: Vec3) {
        self.x -= o.x;
        self.y -= o.y;
        self.z -= o.z;
    }
}
