//! Parameters: numbered `#1`-`#5601` (`#1`-`#30` local to a call), named locals `#<name>` per
//! call level and globals `#<_name>`. The predefined read-only ones (`#5400`-`#5413`,
//! `#5420`-`#5428`, `#<_x>`, `#<_metric>`, ...) are answered by the interpreter's state
//! ([`super::interp`]); this is the store.

use std::collections::HashMap;
use std::string::String;
use std::vec;
use std::vec::Vec;

/// Highest numbered parameter (LinuxCNC's `RS274NGC_MAX_PARAMETERS - 1`).
pub const MAX_PARAMETER: i64 = 5601;

/// Most named parameters one program may create: 100,000 (each costs its name and a value;
/// a loop creating names without end is refused, not a growing heap).
pub const MAX_NAMED_PARAMETERS: usize = 100_000;

/// Numbered and named parameters.
#[derive(Debug, Clone)]
pub(super) struct Params {
    numbered: Vec<f64>,
    globals: HashMap<String, f64>,
    /// Locals per call level (index 0: the main program).
    locals: Vec<HashMap<String, f64>>,
    named: usize,
}

impl Params {
    pub(super) fn new() -> Self {
        let mut numbered = vec![0.0; MAX_PARAMETER as usize + 1];
        // #5599: (DEBUG,...) output on, #5220: G54 active.
        if let Some(v) = numbered.get_mut(5599) {
            *v = 1.0;
        }
        if let Some(v) = numbered.get_mut(5220) {
            *v = 1.0;
        }
        Self {
            numbered,
            globals: HashMap::new(),
            locals: vec![HashMap::new()],
            named: 0,
        }
    }

    /// `#index`, index in 1..=5601 (checked by the caller).
    pub(super) fn get(&self, index: usize) -> f64 {
        self.numbered.get(index).copied().unwrap_or(0.0)
    }

    /// Sets `#index` (index checked by the caller).
    pub(super) fn set(&mut self, index: usize, v: f64) {
        if let Some(p) = self.numbered.get_mut(index) {
            *p = v;
        }
    }

    fn scope(&self, name: &str) -> Option<&HashMap<String, f64>> {
        if name.starts_with('_') {
            Some(&self.globals)
        } else {
            self.locals.last()
        }
    }

    /// A named parameter's value, if it exists.
    pub(super) fn named(&self, name: &str) -> Option<f64> {
        self.scope(name).and_then(|m| m.get(name).copied())
    }

    /// Sets (or creates) a named parameter; `Err` past [`MAX_NAMED_PARAMETERS`].
    pub(super) fn set_named(&mut self, name: &str, v: f64) -> Result<(), String> {
        let map = if name.starts_with('_') {
            &mut self.globals
        } else {
            match self.locals.last_mut() {
                Some(m) => m,
                None => &mut self.globals,
            }
        };
        if let Some(p) = map.get_mut(name) {
            *p = v;
            return Ok(());
        }
        if self.named >= MAX_NAMED_PARAMETERS {
            return Err(std::format!(
                "at most {MAX_NAMED_PARAMETERS} named parameters (MAX_NAMED_PARAMETERS)"
            ));
        }
        self.named += 1;
        map.insert(name.into(), v);
        Ok(())
    }

    /// Enters a call: a new local scope; returns the caller's `#1`-`#30`.
    pub(super) fn enter(&mut self) -> [f64; 30] {
        self.locals.push(HashMap::new());
        let mut saved = [0.0; 30];
        for (k, s) in saved.iter_mut().enumerate() {
            *s = self.get(k + 1);
        }
        saved
    }

    /// Leaves a call: drops its locals and restores the caller's `#1`-`#30` (when given).
    pub(super) fn leave(&mut self, saved: Option<&[f64; 30]>) {
        if self.locals.len() > 1
            && let Some(m) = self.locals.pop()
        {
            self.named = self.named.saturating_sub(m.len());
        }
        if let Some(saved) = saved {
            for (k, s) in saved.iter().enumerate() {
                self.set(k + 1, *s);
            }
        }
    }
}
