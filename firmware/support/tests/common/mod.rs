//! A NOR flash in RAM with the ESP32's geometry, for the durable log's tests.
#![allow(dead_code)]

use embedded_storage::nor_flash::{
    check_erase, check_read, check_write, ErrorType, NorFlash, NorFlashErrorKind, ReadNorFlash,
};

/// The erase unit.
pub const SECTOR: usize = 4096;

/// NOR flash in RAM: erase sets 0xFF, a write can only clear bits. `budget` counts the octets
/// (erased or programmed) left before the power fails: the operation in progress stops part
/// way and every later one fails, until [`Ram::reset`].
#[derive(Clone)]
pub struct Ram {
    pub mem: Vec<u8>,
    pub budget: Option<usize>,
    /// Octets programmed while not erased (a store bug on real flash).
    pub overwrites: usize,
    pub erases: usize,
    /// The power failed.
    pub dead: bool,
}

impl Ram {
    pub fn new(sectors: usize) -> Ram {
        Ram {
            // Not erased: a new chip's content is unknown.
            mem: vec![0x3C; sectors * SECTOR],
            budget: None,
            overwrites: 0,
            erases: 0,
            dead: false,
        }
    }
    /// Erased (all `0xFF`): a partition `espflash erase-region` cleared.
    pub fn erased(sectors: usize) -> Ram {
        Ram {
            mem: vec![0xFF; sectors * SECTOR],
            ..Ram::new(sectors)
        }
    }
    /// Holding `image` (a partition image `espflash write-bin` wrote).
    pub fn from_image(image: &[u8]) -> Ram {
        assert_eq!(image.len() % SECTOR, 0);
        Ram {
            mem: image.to_vec(),
            ..Ram::new(image.len() / SECTOR)
        }
    }
    pub fn reset(mut self) -> Ram {
        self.budget = None;
        self.dead = false;
        self
    }
    /// Spends one octet of the power budget; false once the power is gone.
    fn spend(&mut self) -> bool {
        if self.dead {
            return false;
        }
        match &mut self.budget {
            None => true,
            Some(0) => {
                self.dead = true;
                false
            }
            Some(n) => {
                *n -= 1;
                true
            }
        }
    }
}

impl ErrorType for Ram {
    type Error = NorFlashErrorKind;
}

impl ReadNorFlash for Ram {
    const READ_SIZE: usize = 4;
    fn read(&mut self, offset: u32, bytes: &mut [u8]) -> Result<(), Self::Error> {
        check_read(self, offset, bytes.len())?;
        if self.dead {
            return Err(NorFlashErrorKind::Other);
        }
        let o = offset as usize;
        bytes.copy_from_slice(&self.mem[o..o + bytes.len()]);
        Ok(())
    }
    fn capacity(&self) -> usize {
        self.mem.len()
    }
}

impl NorFlash for Ram {
    const WRITE_SIZE: usize = 4;
    const ERASE_SIZE: usize = SECTOR;
    fn erase(&mut self, from: u32, to: u32) -> Result<(), Self::Error> {
        check_erase(self, from, to)?;
        self.erases += 1;
        for i in from as usize..to as usize {
            if !self.spend() {
                return Err(NorFlashErrorKind::Other);
            }
            self.mem[i] = 0xFF;
        }
        Ok(())
    }
    fn write(&mut self, offset: u32, bytes: &[u8]) -> Result<(), Self::Error> {
        check_write(self, offset, bytes.len())?;
        for (i, b) in bytes.iter().enumerate() {
            if !self.spend() {
                return Err(NorFlashErrorKind::Other);
            }
            let at = &mut self.mem[offset as usize + i];
            if *at != 0xFF {
                self.overwrites += 1;
            }
            *at &= b;
        }
        Ok(())
    }
}
