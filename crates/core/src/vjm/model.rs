//! The immutable chain model and its builder.

use nalgebra::{Isometry3, Matrix3, Unit, Vector3};

use super::chain::{AxisKind, Shape};
use crate::error::BuildError;

/// Most actuated joints a model may have: a 6-axis arm plus a linear track and a turntable,
/// the largest cell the machining papers consider. Sizes the fixed Jacobian in [`crate::vjm::Data`].
pub const MAX_DOF: usize = 8;
/// Most virtual joints: the paper's KR 300 model has 11 (Table 1); 32 leaves room for a
/// spring per joint and per link of an 8-axis cell with a multi-part end effector.
pub const MAX_SPRINGS: usize = 32;
/// Most link masses: the chain's own ([`Element::Mass`], loads under motion) and the point
/// masses of a drive-train model ([`crate::drivetrain::LinkMasses`]); one per link of the
/// largest chain with its tool, sensor and payload parts.
pub const MAX_MASSES: usize = 32;
/// Most chain elements after merging consecutive fixed transforms. A spring placed inside a
/// link costs up to three elements (offset, spring, inverse offset), a joint two; 4 * 32
/// covers [`MAX_SPRINGS`] springs and [`MAX_DOF`] joints with their fixed origins.
pub const MAX_ELEMENTS: usize = 128;

/// One link of the kinematic chain, applied left to right from the base to the TCP.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Element {
    /// A constant transform (URDF joint origins, fixed joints, tool offsets).
    Fixed(Isometry3<f64>),
    /// A revolute joint about `axis` of the current frame; angle `q[index]` \[rad\].
    Revolute {
        /// Unit axis in the current frame.
        axis: Unit<Vector3<f64>>,
        /// Index into the joint vector.
        index: usize,
    },
    /// A prismatic joint along `axis` of the current frame; travel `q[index]` \[m\].
    Prismatic {
        /// Unit axis in the current frame.
        axis: Unit<Vector3<f64>>,
        /// Index into the joint vector.
        index: usize,
    },
    /// A virtual joint whose frame sits at `offset` from the current frame (identity: at the
    /// current frame): compliances `1/k` \[rad / (N m)\] about the spring frame's x, y, z axes
    /// (k_C, k_B, k_A of Table 1). A compliance of 0 is a rigid axis. The chain continues
    /// from the current frame (the offset only places the spring).
    Spring {
        /// `[1/k_C, 1/k_B, 1/k_A]` \[rad / (N m)\].
        compliance: Vector3<f64>,
        /// Index of the spring in chain order.
        index: usize,
        /// Spring frame relative to the current frame.
        offset: Isometry3<f64>,
    },
    /// A rigid body attached to the current frame: mass \[kg\], centre of mass \[m\] and
    /// inertia about the centre of mass \[kg m^2\], both in the current frame. It changes no
    /// kinematics; under joint motion its inertial wrench loads every spring before it
    /// ([`crate::vjm::Load::ExactWithArm`]).
    Mass {
        /// Mass \[kg\].
        mass: f64,
        /// Centre of mass in the current frame \[m\].
        com: Vector3<f64>,
        /// Inertia about the centre of mass, current-frame axes \[kg m^2\].
        inertia: Matrix3<f64>,
        /// Index of the mass in chain order.
        index: usize,
    },
}

/// The chain compiled for the kernels at build time: each joint carries the fixed transform
/// before it (one composition instead of two per joint), spring offsets are kept aside (the
/// chain does not pass through them), and only a trailing fixed transform stays alone.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Op {
    Fixed(Isometry3<f64>),
    Joint {
        pre: Isometry3<f64>,
        axis: Unit<Vector3<f64>>,
        revolute: bool,
        index: usize,
    },
    Spring {
        offset: Option<Isometry3<f64>>,
        compliance: Vector3<f64>,
        index: usize,
    },
    /// A mass in the frame of the op before (any pending fixed transform folded into it).
    Mass {
        mass: f64,
        com: Vector3<f64>,
        inertia: Matrix3<f64>,
        index: usize,
    },
}

/// One actuated joint of the chain with springs and masses taken out: what the rigid TCP
/// pose alone needs ([`super::forward`]), every fixed transform before it folded into `pre`.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct TcpStep {
    pub pre: Isometry3<f64>,
    /// What `pre` does ([`super::chain::compose`]).
    pub pre_shape: Shape,
    pub axis: Unit<Vector3<f64>>,
    /// `axis` as the specialised compositions take it.
    pub kind: AxisKind,
    pub revolute: bool,
    pub index: usize,
}

/// The rigid pass compiled at build: the joints with the fixed transforms between them
/// folded (across springs and masses), and each spring's frame relative to the frame after
/// the joint before it, so every spring costs one composition and the chain one per joint.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Pass {
    /// The joint `tcp_chain[k]`.
    Joint(usize),
    Spring {
        local: Isometry3<f64>,
        /// What `local` does ([`super::chain::compose`]).
        shape: Shape,
        index: usize,
    },
}

/// An immutable serial chain with virtual joints, built once by [`ModelBuilder`] or loaded by
/// [`crate::SerialRobot`]. Holds no heap memory, so it can live in a static on a controller.
#[derive(Debug, Clone, PartialEq)]
pub struct Model {
    pub(crate) elements: heapless::Vec<Element, MAX_ELEMENTS>,
    pub(crate) ops: heapless::Vec<Op, MAX_ELEMENTS>,
    /// The joints alone, fixed transforms folded across the springs and masses between them.
    pub(crate) tcp_chain: heapless::Vec<TcpStep, MAX_DOF>,
    /// Joints and springs for the pass that also places the springs.
    pub(crate) pass: heapless::Vec<Pass, { MAX_DOF + MAX_SPRINGS }>,
    /// The fixed transform after the last joint.
    pub(crate) tcp_tail: Isometry3<f64>,
    /// Each spring's compliances by spring index (zero past the spring count), for the
    /// lane-parallel kernels.
    pub(crate) spring_compliance: [Vector3<f64>; MAX_SPRINGS],
    pub(crate) dof: usize,
    pub(crate) springs: usize,
    pub(crate) masses: usize,
}

impl Model {
    /// Number of actuated joints (length of `q`).
    pub fn dof(&self) -> usize {
        self.dof
    }
    /// Number of virtual joints.
    pub fn spring_count(&self) -> usize {
        self.springs
    }
    /// Number of link masses ([`Element::Mass`]).
    pub fn mass_count(&self) -> usize {
        self.masses
    }
    /// The chain, base to TCP.
    pub fn elements(&self) -> &[Element] {
        &self.elements
    }
}

/// Builds a [`Model`] element by element, without a heap.
///
/// ```
/// use deflect_core::ModelBuilder;
/// use nalgebra::{Isometry3, Vector3};
/// // A 1 m arm about z, with one spring at the joint that is soft about z.
/// let model = ModelBuilder::new()
///     .revolute(Vector3::z())?
///     .spring([f64::INFINITY, f64::INFINITY, 1.0e4])?
///     .fixed(Isometry3::translation(1.0, 0.0, 0.0))?
///     .build()?;
/// assert_eq!(model.dof(), 1);
/// # Ok::<(), deflect_core::BuildError>(())
/// ```
#[derive(Debug, Clone, Default)]
pub struct ModelBuilder {
    elements: heapless::Vec<Element, MAX_ELEMENTS>,
    dof: usize,
    springs: usize,
    masses: usize,
    calls: usize,
}

impl ModelBuilder {
    /// An empty chain (the TCP is the base frame).
    pub fn new() -> Self {
        Self::default()
    }

    fn push(&mut self, e: Element) -> Result<(), BuildError> {
        self.elements.push(e).map_err(|_| BuildError::Capacity {
            what: "elements",
            capacity: MAX_ELEMENTS,
            got: MAX_ELEMENTS + 1,
        })
    }

    /// Appends a constant transform (merged with a preceding one).
    pub fn fixed(mut self, t: Isometry3<f64>) -> Result<Self, BuildError> {
        let element = self.calls;
        self.calls += 1;
        if !iso_is_finite(&t) {
            return Err(BuildError::NonFinite {
                what: "transform",
                index: element,
            });
        }
        if let Some(Element::Fixed(prev)) = self.elements.last_mut() {
            *prev *= t;
        } else {
            self.push(Element::Fixed(t))?;
        }
        Ok(self)
    }

    fn joint(mut self, axis: Vector3<f64>, revolute: bool) -> Result<Self, BuildError> {
        let element = self.calls;
        self.calls += 1;
        let norm = axis.norm();
        if !(norm.is_finite() && norm > 0.0) {
            return Err(BuildError::ZeroAxis { element });
        }
        if self.dof >= MAX_DOF {
            return Err(BuildError::Capacity {
                what: "joints",
                capacity: MAX_DOF,
                got: MAX_DOF + 1,
            });
        }
        let axis = Unit::new_normalize(axis);
        let index = self.dof;
        self.push(if revolute {
            Element::Revolute { axis, index }
        } else {
            Element::Prismatic { axis, index }
        })?;
        self.dof += 1;
        Ok(self)
    }

    /// Appends a revolute joint about `axis` (any non-zero length) of the current frame.
    pub fn revolute(self, axis: Vector3<f64>) -> Result<Self, BuildError> {
        self.joint(axis, true)
    }

    /// Appends a prismatic joint along `axis` (any non-zero length) of the current frame.
    pub fn prismatic(self, axis: Vector3<f64>) -> Result<Self, BuildError> {
        self.joint(axis, false)
    }

    /// Appends a virtual joint at the current frame with stiffnesses `k = [k_C, k_B, k_A]`
    /// \[N m / rad\] about its x, y, z axes; `f64::INFINITY` makes an axis rigid (see
    /// [`valid_stiffness`]).
    pub fn spring(mut self, k: [f64; 3]) -> Result<Self, BuildError> {
        let element = self.calls;
        self.calls += 1;
        let mut compliance = Vector3::zeros();
        for (axis, (&ki, ci)) in k.iter().zip(compliance.iter_mut()).enumerate() {
            // Zero, negative, NaN and sub-normal values are refused: 1/k of a sub-normal
            // overflows to infinity and turns every deflection into NaN.
            if !valid_stiffness(ki) {
                return Err(BuildError::NonPositiveStiffness {
                    element,
                    axis,
                    value: ki,
                });
            }
            *ci = 1.0 / ki; // 0 for +inf: rigid
        }
        if self.springs >= MAX_SPRINGS {
            return Err(BuildError::Capacity {
                what: "springs",
                capacity: MAX_SPRINGS,
                got: MAX_SPRINGS + 1,
            });
        }
        let index = self.springs;
        self.push(Element::Spring {
            compliance,
            index,
            offset: Isometry3::identity(),
        })?;
        self.springs += 1;
        Ok(self)
    }

    /// Appends a virtual joint whose frame sits at `frame` relative to the current frame
    /// (an offset and orientation inside a link); the chain continues from the current frame.
    pub fn spring_at(self, frame: Isometry3<f64>, k: [f64; 3]) -> Result<Self, BuildError> {
        if !iso_is_finite(&frame) {
            return Err(BuildError::NonFinite {
                what: "spring frame",
                index: self.calls,
            });
        }
        let mut b = self.spring(k)?;
        if let Some(Element::Spring { offset, .. }) = b.elements.last_mut() {
            *offset = frame;
        }
        Ok(b)
    }

    /// Appends a rigid body at the current frame: `mass` \[kg\] (finite, >= 0), centre of mass
    /// `com` \[m\] and `inertia` about it \[kg m^2\] (symmetric, positive semi-definite), both
    /// in the current frame. Kinematics are unchanged; under joint motion its inertial wrench
    /// loads the springs before it.
    pub fn mass(
        mut self,
        mass: f64,
        com: Vector3<f64>,
        inertia: Matrix3<f64>,
    ) -> Result<Self, BuildError> {
        let element = self.calls;
        self.calls += 1;
        if !mass.is_finite() || com.iter().chain(inertia.iter()).any(|v| !v.is_finite()) {
            return Err(BuildError::NonFinite {
                what: "link mass properties",
                index: element,
            });
        }
        crate::error::param("link mass", mass, mass >= 0.0, ">= 0 (kg)")?;
        let scale = inertia.amax().max(f64::MIN_POSITIVE);
        let asym = (inertia - inertia.transpose()).amax();
        if asym > 1e-9 * scale {
            return Err(BuildError::InvalidParameter {
                what: "link inertia (asymmetry)",
                value: asym,
                expected: "a symmetric tensor",
            });
        }
        let min = inertia.symmetric_eigenvalues().min();
        if min < -1e-9 * scale {
            return Err(BuildError::Singular {
                what: "link inertia (not positive semi-definite)",
                measure: min,
            });
        }
        if self.masses >= MAX_MASSES {
            return Err(BuildError::Capacity {
                what: "masses",
                capacity: MAX_MASSES,
                got: MAX_MASSES + 1,
            });
        }
        let index = self.masses;
        self.push(Element::Mass {
            mass,
            com,
            inertia,
            index,
        })?;
        self.masses += 1;
        Ok(self)
    }

    /// Appends `e` as it is, a model's own element ([`Model::elements`], e.g. of a model
    /// saved and read back): validated like the other calls, joint, spring and mass indices
    /// renumbered, and the values kept bit for bit (a unit axis is not normalized again, a
    /// compliance not inverted twice), so that a rebuilt model computes exactly what the
    /// original did. Rotations (fixed transforms, spring frames) and axes must be unit within
    /// 1e-9; compliances 0 (rigid) or normal and positive.
    pub fn element(self, e: Element) -> Result<Self, BuildError> {
        let unit = |what: &'static str, norm: f64| {
            if (norm - 1.0).abs() <= 1e-9 {
                Ok(())
            } else {
                Err(BuildError::InvalidParameter {
                    what,
                    value: norm,
                    expected: "unit length (within 1e-9)",
                })
            }
        };
        match e {
            Element::Fixed(t) => {
                unit(
                    "fixed transform rotation (quaternion norm)",
                    t.rotation.coords.norm(),
                )?;
                self.fixed(t)
            }
            Element::Revolute { axis, .. } | Element::Prismatic { axis, .. } => {
                unit("joint axis (norm)", axis.norm())?;
                let revolute = matches!(e, Element::Revolute { .. });
                let mut b = self.joint(axis.into_inner(), revolute)?;
                if let Some(
                    Element::Revolute { axis: a, .. } | Element::Prismatic { axis: a, .. },
                ) = b.elements.last_mut()
                {
                    *a = axis;
                }
                Ok(b)
            }
            Element::Spring {
                compliance, offset, ..
            } => {
                unit(
                    "spring frame rotation (quaternion norm)",
                    offset.rotation.coords.norm(),
                )?;
                let mut k = [f64::INFINITY; 3];
                for (axis, (&c, ki)) in compliance.iter().zip(k.iter_mut()).enumerate() {
                    if c == 0.0 {
                        continue;
                    }
                    if !(c.is_normal() && c > 0.0) {
                        return Err(BuildError::NonPositiveStiffness {
                            element: self.calls,
                            axis,
                            value: 1.0 / c,
                        });
                    }
                    *ki = 1.0 / c;
                }
                let mut b = self.spring_at(offset, k)?;
                if let Some(Element::Spring { compliance: c, .. }) = b.elements.last_mut() {
                    *c = compliance;
                }
                Ok(b)
            }
            Element::Mass {
                mass, com, inertia, ..
            } => self.mass(mass, com, inertia),
        }
    }

    /// Finishes the model (and compiles it for the kernels).
    pub fn build(self) -> Result<Model, BuildError> {
        let ops = compile_ops(&self.elements)?;
        let (tcp_chain, pass, tail) = compile_pass(&self.elements)?;
        let mut spring_compliance = [Vector3::zeros(); MAX_SPRINGS];
        for e in &self.elements {
            if let Element::Spring {
                compliance, index, ..
            } = e
                && let Some(slot) = spring_compliance.get_mut(*index)
            {
                *slot = *compliance;
            }
        }
        Ok(Model {
            spring_compliance,
            elements: self.elements,
            ops,
            tcp_chain,
            pass,
            tcp_tail: tail,
            dof: self.dof,
            springs: self.springs,
            masses: self.masses,
        })
    }
}

/// The error of a compiled table past [`MAX_ELEMENTS`].
const ELEMENTS_CAPACITY: BuildError = BuildError::Capacity {
    what: "elements",
    capacity: MAX_ELEMENTS,
    got: MAX_ELEMENTS + 1,
};

/// The chain compiled for the kernels ([`Op`]): each fixed transform folded into the next
/// joint, masses expressed before a pending one.
fn compile_ops(elements: &[Element]) -> Result<heapless::Vec<Op, MAX_ELEMENTS>, BuildError> {
    let mut ops: heapless::Vec<Op, MAX_ELEMENTS> = heapless::Vec::new();
    let capacity = ELEMENTS_CAPACITY;
    // A fixed transform waiting to be folded into the next joint.
    let mut pending: Option<Isometry3<f64>> = None;
    for e in elements {
        let op = match *e {
            Element::Fixed(t) => {
                pending = Some(pending.map_or(t, |p| p * t));
                continue;
            }
            Element::Revolute { axis, index } | Element::Prismatic { axis, index } => Op::Joint {
                pre: pending.take().unwrap_or_else(Isometry3::identity),
                axis,
                revolute: matches!(e, Element::Revolute { .. }),
                index,
            },
            Element::Spring {
                compliance,
                index,
                offset,
            } => {
                if let Some(p) = pending.take() {
                    ops.push(Op::Fixed(p)).map_err(|_| capacity)?;
                }
                Op::Spring {
                    offset: (offset != Isometry3::identity()).then_some(offset),
                    compliance,
                    index,
                }
            }
            Element::Mass {
                mass,
                com,
                inertia,
                index,
            } => {
                // Expressed in the frame before a pending fixed transform, so that the
                // transform still folds into the next joint.
                let p = pending.unwrap_or_else(Isometry3::identity);
                let r = p.rotation.to_rotation_matrix();
                Op::Mass {
                    mass,
                    com: p.transform_point(&com.into()).coords,
                    inertia: r.matrix() * inertia * r.matrix().transpose(),
                    index,
                }
            }
        };
        ops.push(op).map_err(|_| capacity)?;
    }
    if let Some(p) = pending {
        ops.push(Op::Fixed(p)).map_err(|_| capacity)?;
    }
    Ok(ops)
}

/// The rigid pass compiled ([`TcpStep`], [`Pass`]): the joints, the springs' frames relative
/// to the frame after the joint before them, and the fixed transform after the last joint.
type Compiled = (
    heapless::Vec<TcpStep, MAX_DOF>,
    heapless::Vec<Pass, { MAX_DOF + MAX_SPRINGS }>,
    Isometry3<f64>,
);

/// The rigid pass of the chain (see [`Compiled`]). Springs and masses leave the rigid chain
/// as it is: without them, the fixed transforms between two joints fold into one.
fn compile_pass(elements: &[Element]) -> Result<Compiled, BuildError> {
    let capacity = ELEMENTS_CAPACITY;
    let mut tcp_chain: heapless::Vec<TcpStep, MAX_DOF> = heapless::Vec::new();
    let mut pass: heapless::Vec<Pass, { MAX_DOF + MAX_SPRINGS }> = heapless::Vec::new();
    let mut tail = Isometry3::identity();
    for e in elements {
        match *e {
            Element::Fixed(t) => tail *= t,
            Element::Revolute { axis, index } | Element::Prismatic { axis, index } => {
                let pre = core::mem::replace(&mut tail, Isometry3::identity());
                let step = TcpStep {
                    pre_shape: Shape::of(&pre),
                    pre,
                    axis,
                    kind: AxisKind::of(&axis),
                    revolute: matches!(e, Element::Revolute { .. }),
                    index,
                };
                pass.push(Pass::Joint(tcp_chain.len()))
                    .map_err(|_| capacity)?;
                tcp_chain.push(step).map_err(|_| BuildError::Capacity {
                    what: "joints",
                    capacity: MAX_DOF,
                    got: MAX_DOF + 1,
                })?;
            }
            Element::Spring { offset, index, .. } => {
                let local = tail * offset;
                pass.push(Pass::Spring {
                    shape: Shape::of(&local),
                    local,
                    index,
                })
                .map_err(|_| capacity)?;
            }
            Element::Mass { .. } => {}
        }
    }
    Ok((tcp_chain, pass, tail))
}

/// A virtual-joint stiffness \[N m / rad\]: a normal positive number, or `+inf` (rigid).
pub fn valid_stiffness(k: f64) -> bool {
    k == f64::INFINITY || (k.is_normal() && k > 0.0)
}

fn iso_is_finite(t: &Isometry3<f64>) -> bool {
    t.translation.vector.iter().all(|v| v.is_finite())
        && t.rotation.coords.iter().all(|v| v.is_finite())
}

#[cfg(test)]
mod size {
    /// A `Model` holds no heap memory and is often built on the stack (debug builds copy it
    /// on every move): its compiled passes must not grow it much past the element tables.
    #[test]
    fn model_stays_under_36_kib() {
        let size = core::mem::size_of::<super::Model>();
        assert!(size <= 36 * 1024, "Model is {size} bytes");
    }
}
