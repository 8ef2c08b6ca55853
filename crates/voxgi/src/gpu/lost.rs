//! Noticing a lost device (a driver reset, a removed GPU, `Device::destroy`): wgpu reports it
//! once, through a callback, and afterwards every call on the device fails in ways that name
//! neither the loss nor what to do (a failed buffer mapping, an invalid resource, a panic in
//! a helper). Whoever opens a device watches it; voxgi then answers `Error::DeviceLost`.

use crate::{Error, Result};
use std::sync::{Arc, Mutex};

/// Whether a device was lost, and why, as its lost callback said.
#[derive(Clone, Debug, Default)]
pub struct DeviceWatch {
    lost: Arc<Mutex<Option<String>>>,
}

impl DeviceWatch {
    /// Installs `device`'s lost callback (one per device: an application that installs its
    /// own instead can report the loss to voxgi with `mark_lost`).
    pub fn new(device: &wgpu::Device) -> Self {
        let watch = DeviceWatch::default();
        let lost = watch.lost.clone();
        device.set_device_lost_callback(move |reason, message| {
            let why = match reason {
                wgpu::DeviceLostReason::Destroyed => "the device was destroyed".to_string(),
                wgpu::DeviceLostReason::Unknown if message.is_empty() => {
                    "the driver reset it or the GPU was removed".to_string()
                }
                wgpu::DeviceLostReason::Unknown => message,
            };
            log::error!("GPU device lost: {why}");
            if let Ok(mut l) = lost.lock() {
                l.get_or_insert(why);
            }
        });
        watch
    }

    /// Records a loss the application noticed itself.
    pub fn mark_lost(&self, why: impl Into<String>) {
        if let Ok(mut l) = self.lost.lock() {
            l.get_or_insert(why.into());
        }
    }

    /// Why the device was lost, if it was.
    pub fn lost(&self) -> Option<String> {
        self.lost.lock().ok().and_then(|l| l.clone())
    }

    /// `Error::DeviceLost` once the device is lost.
    pub fn check(&self) -> Result<()> {
        match self.lost() {
            Some(reason) => Err(Error::DeviceLost { reason }),
            None => Ok(()),
        }
    }

    /// `result`, unless the device was lost meanwhile: then `Error::DeviceLost`, which names
    /// the cause the failure itself does not.
    pub fn explain<T>(&self, result: Result<T>) -> Result<T> {
        match (result, self.lost()) {
            (Err(_), Some(reason)) => Err(Error::DeviceLost { reason }),
            (r, _) => r,
        }
    }
}
