//! The streamed writer every language shares: the decimation, the line comments, the dwells,
//! the speeds and blends, and the dispatch to the language's module.

use std::io::Write;
use std::string::{String, ToString};

use nalgebra::UnitQuaternion;

use super::context::{Context, pose};
use super::{
    Command, Language, ORIENTATION_LEVER, ProgramError, ProgramFile, ProgramOptions, Target, csv,
    krl, rapid, urscript,
};
use crate::geometry::distance_to_segment;
use crate::io::decimate::{Decimator, Kept};
use crate::machining::job::JobSample;
use crate::vjm::Data;

/// Whether the straight motion from `a` to `b` holds `x`: the TCP within `tolerance` of the
/// chord and its orientation within `tolerance / ORIENTATION_LEVER` of the interpolated one.
fn pose_holds(tolerance: f64, a: &JobSample, b: &JobSample, x: &JobSample) -> bool {
    let (pa, pb, px) = (pose(a), pose(b), pose(x));
    let (ta, tb, tx) = (
        pa.translation.vector,
        pb.translation.vector,
        px.translation.vector,
    );
    if distance_to_segment(&tx, &ta, &tb) > tolerance {
        return false;
    }
    let length = (tb - ta).norm();
    let t = if length > 0.0 {
        ((tx - ta).dot(&(tb - ta)) / (length * length)).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let between: UnitQuaternion<f64> = pa.rotation.slerp(&pb.rotation, t);
    between.angle_to(&px.rotation) <= tolerance / ORIENTATION_LEVER
}

/// Whether the joint motion from `a` to `b` (linear in time) holds `x` within `tolerance`.
fn joints_hold(tolerance: f64, dof: usize, a: &JobSample, b: &JobSample, x: &JobSample) -> bool {
    let span = b.path.time - a.path.time;
    let t = if span > 0.0 {
        ((x.path.time - a.path.time) / span).clamp(0.0, 1.0)
    } else {
        0.0
    };
    a.q_commanded
        .iter()
        .zip(&b.q_commanded)
        .zip(&x.q_commanded)
        .take(dof)
        .all(|((qa, qb), qx)| (qa + (qb - qa) * t - qx).abs() <= tolerance)
}

/// Writes `text` to `out` once it holds 64 KiB, and clears it.
fn spill<W: Write>(out: &mut W, text: &mut String) -> std::io::Result<()> {
    if text.len() > 1 << 16 {
        out.write_all(text.as_bytes())?;
        text.clear();
    }
    Ok(())
}

/// A robot program written as the samples come: [`Self::push`] each chunk in time order,
/// then [`Self::finish`]; the main file streams to the writer, its companion (KRL's `.dat`,
/// fixed by the target) is [`Self::companion`]. Memory: one window of the decimation.
#[derive(Debug)]
pub struct RobotProgram<'a, W: Write> {
    out: W,
    cx: Context<'a>,
    decimator: Decimator,
    started: bool,
    text: String,
}

impl<'a, W: Write> RobotProgram<'a, W> {
    /// A writer of `options`' program for `target` to `out`; checks the options and that the
    /// robot's convention is the language's vendor's.
    pub fn new(out: W, target: Target<'a>, options: &ProgramOptions) -> Result<Self, ProgramError> {
        options.validate()?;
        if let Some(vendor) = options.language.vendor() {
            match target.convention {
                None => {
                    return Err(ProgramError::NoConvention {
                        robot: target.robot.to_string(),
                        language: options.language,
                    });
                }
                Some(c) if c.vendor != vendor => {
                    return Err(ProgramError::WrongVendor {
                        robot: target.robot.to_string(),
                        language: options.language,
                        got: c.vendor,
                    });
                }
                Some(_) => {}
            }
        }
        Ok(Self {
            out,
            cx: Context {
                target,
                options: options.clone(),
                data: Data::new(target.model),
                line: usize::MAX,
                speed: f64::NAN,
                blend: f64::NAN,
                dwelt: usize::MAX,
                motions: 0,
            },
            decimator: Decimator::default(),
            started: false,
            text: String::new(),
        })
    }

    /// The main file's name (`deflect_job.src`).
    pub fn file_name(&self) -> String {
        std::format!(
            "{}.{}",
            self.cx.options.name,
            self.cx.options.language.extension()
        )
    }

    /// The companion file (KRL's `.dat`: the frames), known before any sample.
    pub fn companion(&self) -> Option<ProgramFile> {
        match self.cx.options.language {
            Language::Krl => Some(ProgramFile {
                name: std::format!("{}.dat", self.cx.options.name),
                text: krl::dat(&self.cx),
            }),
            _ => None,
        }
    }

    /// Whether the command keeps every sample (URScript's `servoj`, the joints CSV).
    fn every_sample(&self) -> bool {
        self.cx.options.command == Command::Joints
            && matches!(self.cx.options.language, Language::UrScript | Language::Csv)
    }

    /// Hands `s` to the decimation (`None`: the end), writing the motions it keeps.
    fn decimate(&mut self, s: Option<&JobSample>) -> Result<(), ProgramError> {
        let (language, command) = (self.cx.options.language, self.cx.options.command);
        let (tol, jtol, dof) = (
            self.cx.options.tolerance,
            self.cx.options.joint_tolerance,
            self.cx.target.model.dof(),
        );
        let holds = |a: &JobSample, b: &JobSample, x: &JobSample| match command {
            Command::Cartesian => pose_holds(tol, a, b, x),
            Command::Joints => joints_hold(jtol, dof, a, b, x),
        };
        let mut failed = None;
        let (cx, text) = (&mut self.cx, &mut self.text);
        let mut keep = |k: &Kept| {
            if failed.is_none()
                && let Err(e) = motion(language, command, text, cx, k)
            {
                failed = Some(e);
            }
        };
        match s {
            Some(s) => self.decimator.push(s, &holds, &mut keep),
            None => self.decimator.finish(&holds, &mut keep),
        }
        failed.map_or(Ok(()), Err)
    }

    /// The next samples, in time order.
    pub fn push(&mut self, chunk: &[JobSample]) -> Result<(), ProgramError> {
        let language = self.cx.options.language;
        let command = self.cx.options.command;
        for s in chunk {
            if !self.started {
                self.started = true;
                header(language, command, &mut self.text, &mut self.cx, s)?;
            }
            if self.every_sample() {
                let k = Kept {
                    sample: *s,
                    stop: false,
                };
                motion(language, command, &mut self.text, &mut self.cx, &k)?;
            } else {
                self.decimate(Some(s))?;
            }
            spill(&mut self.out, &mut self.text)?;
        }
        Ok(())
    }

    /// Writes the last motion and the program's end; hands back the output.
    pub fn finish(mut self) -> Result<W, ProgramError> {
        let language = self.cx.options.language;
        if !self.every_sample() {
            self.decimate(None)?;
        }
        footer(language, &mut self.text, &self.cx);
        self.out.write_all(self.text.as_bytes())?;
        self.out.flush()?;
        Ok(self.out)
    }
}

fn header(
    language: Language,
    command: Command,
    out: &mut String,
    cx: &mut Context<'_>,
    first: &JobSample,
) -> Result<(), ProgramError> {
    match language {
        Language::Krl => krl::header(out, cx, command, first),
        Language::Rapid => rapid::header(out, cx, command, first),
        Language::UrScript => urscript::header(out, cx, command, first),
        Language::Csv => {
            csv::header(out, cx, command);
            Ok(())
        }
    }
}

fn motion(
    language: Language,
    command: Command,
    out: &mut String,
    cx: &mut Context<'_>,
    k: &Kept,
) -> Result<(), ProgramError> {
    cx.motions += 1;
    match language {
        Language::Krl => krl::motion(out, cx, command, k),
        Language::Rapid => rapid::motion(out, cx, command, k),
        Language::UrScript => urscript::motion(out, cx, command, k),
        Language::Csv => {
            csv::motion(out, cx, command, k);
            Ok(())
        }
    }
}

fn footer(language: Language, out: &mut String, cx: &Context<'_>) {
    match language {
        Language::Krl => krl::footer(out),
        Language::Rapid => rapid::footer(out),
        Language::UrScript => urscript::footer(out, cx),
        Language::Csv => {}
    }
}
